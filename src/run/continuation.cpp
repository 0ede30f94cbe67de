#include "continuation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/input.hpp"

namespace superball {

namespace {

// Cycles and branches travel between ranks as flat arrays of doubles (the one collective
// the MPI layer gathers), written and read in the same order by these two helpers.
class Writer {
public:
    void put(double x) { data_.push_back(x); }
    void put(const CanonicalState<double>& s) { data_.insert(data_.end(), {s.xi, s.U, s.W}); }
    void put(const std::string& s)
    {
        put(static_cast<double>(s.size()));
        for (const char c : s) put(static_cast<double>(static_cast<unsigned char>(c)));
    }
    void put(const std::array<std::complex<double>, 3>& ev)
    {
        for (const auto& z : ev) data_.insert(data_.end(), {z.real(), z.imag()});
    }
    std::vector<double>& data() { return data_; }

private:
    std::vector<double> data_;
};

class Reader {
public:
    explicit Reader(const std::vector<double>& d) : data_(d) {}
    bool done() const { return next_ >= data_.size(); }
    double number() { return data_.at(next_++); }
    int integer() { return static_cast<int>(number()); }
    std::size_t size() { return static_cast<std::size_t>(number()); }
    CanonicalState<double> state()
    {
        const double xi = number(), U = number(), W = number();
        return {xi, U, W};
    }
    std::string text()
    {
        std::string s(size(), ' ');
        for (char& c : s) c = static_cast<char>(static_cast<unsigned char>(number()));
        return s;
    }
    std::array<std::complex<double>, 3> eigenvalues()
    {
        std::array<std::complex<double>, 3> ev;
        for (auto& z : ev) {
            const double re = number(), im = number();
            z = {re, im};
        }
        return ev;
    }

private:
    const std::vector<double>& data_;
    std::size_t next_ = 0;
};

void put_cycle(Writer& w, const Cycle& c)
{
    w.put(c.period);
    w.put(c.corner ? 1.0 : 0.0);
    w.put(c.family ? 1.0 : 0.0);
    w.put(c.lambda);
    w.put(c.residual);
    w.put(static_cast<double>(c.stability));
    w.put(c.eigenvalues);
    for (const auto& p : c.points) w.put(p);
}

Cycle get_cycle(Reader& r)
{
    Cycle c;
    c.period = r.integer();
    c.corner = r.number() != 0.0;
    c.family = r.number() != 0.0;
    c.lambda = r.number();
    c.residual = r.number();
    c.stability = static_cast<Stability>(r.integer());
    c.eigenvalues = r.eigenvalues();
    for (int i = 0; i < c.period; ++i) c.points.push_back(r.state());
    return c;
}

void put_point(Writer& w, const BranchPoint& p)
{
    w.put(p.parameter);
    w.put(p.point);
    w.put(p.representative);
    w.put(p.lambda);
    w.put(p.eigenvalues);
    w.put(static_cast<double>(p.stability));
    w.put(p.residual);
    w.put(p.arclength);
    w.put(static_cast<double>(p.event));
    w.put(p.bracket);
    w.put(p.note);
}

BranchPoint get_point(Reader& r)
{
    BranchPoint p;
    p.parameter = r.number();
    p.point = r.state();
    p.representative = r.state();
    p.lambda = r.number();
    p.eigenvalues = r.eigenvalues();
    p.stability = static_cast<Stability>(r.integer());
    p.residual = r.number();
    p.arclength = r.number();
    p.event = static_cast<BranchEvent>(r.integer());
    p.bracket = r.number();
    p.note = r.text();
    return p;
}

void put_branch(Writer& w, std::size_t index, const std::optional<Branch>& b)
{
    w.put(static_cast<double>(index));
    w.put(b ? 1.0 : 0.0);
    if (!b) return;
    w.put(b->period);
    w.put(static_cast<double>(b->domain));
    w.put(static_cast<double>(b->start));
    w.put(static_cast<double>(b->points.size()));
    for (const BranchPoint& p : b->points) put_point(w, p);
}

std::pair<std::size_t, std::optional<Branch>> get_branch(Reader& r)
{
    const std::size_t index = r.size();
    if (r.number() == 0.0) return {index, std::nullopt};
    Branch b;
    b.period = r.integer();
    b.domain = static_cast<Domain>(r.integer());
    b.start = r.size();
    b.points.resize(r.size());
    for (BranchPoint& p : b.points) p = get_point(r);
    return {index, std::move(b)};
}

void put_curve(Writer& w, std::size_t index, const std::optional<EventCurve>& c)
{
    w.put(static_cast<double>(index));
    w.put(c ? 1.0 : 0.0);
    if (!c) return;
    w.put(static_cast<double>(c->event));
    w.put(c->period);
    w.put(static_cast<double>(c->domain));
    w.put(static_cast<double>(c->start));
    w.put(c->first_end);
    w.put(c->last_end);
    w.put(static_cast<double>(c->points.size()));
    for (const EventCurvePoint& p : c->points) {
        w.put(p.first);
        w.put(p.second);
        put_point(w, p.point);
    }
}

std::pair<std::size_t, std::optional<EventCurve>> get_curve(Reader& r)
{
    const std::size_t index = r.size();
    if (r.number() == 0.0) return {index, std::nullopt};
    EventCurve c;
    c.event = static_cast<BranchEvent>(r.integer());
    c.period = r.integer();
    c.domain = static_cast<Domain>(r.integer());
    c.start = r.size();
    c.first_end = r.text();
    c.last_end = r.text();
    c.points.resize(r.size());
    for (EventCurvePoint& p : c.points) {
        p.first = r.number();
        p.second = r.number();
        p.point = get_point(r);
    }
    return {index, std::move(c)};
}

// One process without MPI (the Python module): what the collectives below come to on a
// single rank.
struct Alone {
    int rank() const { return 0; }
    int size() const { return 1; }
    bool is_root() const { return true; }
    void broadcast(std::vector<double>&) const {}
    std::vector<double> gather(const std::vector<double>& mine) const { return mine; }
};

std::vector<Cycle> search(const ContinuationRun& run, const mpi::Comm& comm) { return find_cycles(run.model, run.search, comm); }
std::vector<Cycle> search(const ContinuationRun& run, const Alone&) { return find_cycles(run.model, run.search); }

// The cycles to start from, the same on every rank.
template <class Team>
std::vector<Cycle> starts(const ContinuationRun& run, const Team& comm)
{
    const ModelMatrices m = ModelMatrices::of(run.model);
    if (run.start) {
        const Domain domain = run.start->xi == 0.0 ? Domain::corner : Domain::interior;
        const auto point = newton_cycle(*run.start, m, run.period, domain);
        const auto cycle = point ? make_cycle(*point, m, run.period, domain) : std::nullopt;
        if (!cycle) {
            throw InputError(run.start_key + " = " + format_double(run.start->xi) + "," + format_double(run.start->U) + "," +
                             format_double(run.start->W) + ": Newton's method finds no cycle of period " +
                             std::to_string(run.period) + " from there" +
                             (domain == Domain::corner ? " on the corner plane" : "") +
                             " (fixed-points lists the cycles)");
        }
        return {*cycle};
    }
    Writer w;
    for (const Cycle& c : search(run, comm)) put_cycle(w, c);
    comm.broadcast(w.data());
    std::vector<Cycle> cycles;
    Reader r(w.data());
    while (!r.done()) cycles.push_back(get_cycle(r));
    return cycles;
}

// Whether `c` (a cycle at the start's parameter) lies on branch b: where b crosses that
// parameter, Newton's method from the interpolated point finds c.
bool on_branch(const Branch& b, const Cycle& c, const ContinuationRun& run)
{
    if (b.period != c.period || (b.domain == Domain::corner) != c.corner) return false;
    const double p0 = parameter_value(run.model, run.parameter);
    const ModelMatrices m = ModelMatrices::of(run.model);
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
        const BranchPoint& a = b.points[i];
        const BranchPoint& z = b.points[i + 1];
        if ((a.parameter - p0) * (z.parameter - p0) > 0.0 || a.parameter == z.parameter) continue;
        const double f = (p0 - a.parameter) / (z.parameter - a.parameter);
        const Eigen::Vector3d x = as_vector(a.point) + f * (as_vector(z.point) - as_vector(a.point));
        const auto point = newton_cycle(as_state(x), m, b.period, b.domain);
        const auto found = point ? make_cycle(*point, m, b.period, b.domain) : std::nullopt;
        if (found && same_cycle(*found, c)) return true;
    }
    return false;
}

bool curve_event(BranchEvent e)
{
    return e == BranchEvent::fold || e == BranchEvent::period_doubling || e == BranchEvent::neimark_sacker || e == BranchEvent::branch_point;
}

// The event curves of the branches (on rank 0), computed curve i on rank i mod size. Every
// rank needs the branches: rank 0 sends them.
template <class Team>
std::vector<ContinuedCurve> continue_curves(const std::vector<ContinuedBranch>& branches, const ContinuationRun& run,
                                            const Team& comm)
{
    Writer all_branches;
    for (std::size_t i = 0; i < branches.size(); ++i) put_branch(all_branches, i, branches[i].branch);
    comm.broadcast(all_branches.data());
    std::vector<std::optional<Branch>> local;
    Reader r(all_branches.data());
    while (!r.done()) local.push_back(get_branch(r).second);

    std::vector<ContinuedCurve> jobs;
    for (std::size_t b = 0; b < local.size(); ++b) {
        if (!local[b]) continue;
        for (std::size_t i = 0; i < local[b]->points.size(); ++i) {
            if (curve_event(local[b]->points[i].event)) jobs.push_back({b, i, std::nullopt});
        }
    }
    Writer mine;
    for (std::size_t j = static_cast<std::size_t>(comm.rank()); j < jobs.size(); j += static_cast<std::size_t>(comm.size())) {
        put_curve(mine, j,
                  continue_event(*local[jobs[j].branch], jobs[j].event, run.model, run.parameter, run.curves->second,
                                 run.curves->settings));
    }
    const std::vector<double> gathered = comm.gather(mine.data());
    if (!comm.is_root()) return {};
    Reader g(gathered);
    while (!g.done()) {
        auto [index, curve] = get_curve(g);
        jobs.at(index).curve = std::move(curve);
    }
    return jobs;
}

template <class Team>
ContinuationResult continue_with(const ContinuationRun& run, const Team& comm)
{
    const std::vector<Cycle> cycles = starts(run, comm);
    Writer mine;
    for (std::size_t i = static_cast<std::size_t>(comm.rank()); i < cycles.size();
         i += static_cast<std::size_t>(comm.size())) {
        put_branch(mine, i, continue_cycle(cycles[i], run.model, run.parameter, run.settings));
    }
    const std::vector<double> all = comm.gather(mine.data());
    ContinuationResult result;
    if (comm.is_root()) {
        result.branches.resize(cycles.size());
        for (std::size_t i = 0; i < cycles.size(); ++i) result.branches[i].start = cycles[i];
        Reader r(all);
        while (!r.done()) {
            auto [index, branch] = get_branch(r);
            result.branches.at(index).branch = std::move(branch);
        }
        // In the order of the starts, so the verdict does not depend on who computed what.
        auto& out = result.branches;
        for (std::size_t j = 0; j < out.size(); ++j) {
            for (std::size_t i = 0; i < j && !out[j].same_as; ++i) {
                if (out[i].branch && !out[i].same_as && on_branch(*out[i].branch, out[j].start, run)) {
                    out[j].same_as = i;
                    out[j].branch.reset();
                }
            }
        }
    }
    if (run.curves) result.curves = continue_curves(result.branches, run, comm);
    return result;
}

// The bounds `lo`, `hi` of coefficient p (keys lo_key, hi_key), checked: set, in range,
// ordered, and around the start's value p0 (from the model).
void check_bounds(Parameter p, const std::optional<double>& lo, const std::optional<double>& hi, const std::string& lo_key,
                  const std::string& hi_key, const std::string& p_name, double p0, const std::string& p0_origin)
{
    const std::string range = parameter_range_text(p);
    for (const auto& [key, value] : {std::pair{&lo_key, lo}, std::pair{&hi_key, hi}}) {
        if (!value) {
            std::string message = *key;  // built with +=: one allocation, not one per piece
            message += " is not set: give the bounds of ";
            message += p_name;
            message += " (accepted ";
            message += range;
            message += ")";
            throw InputError(message);
        }
        if (!parameter_in_range(p, *value)) {
            throw InputError(*key + " = " + format_double(*value) + " is out of range: accepted " + range);
        }
        // mu = inf is a model (the Cross model), not a point a branch can be followed to.
        if (!std::isfinite(*value)) {
            throw InputError(*key + " = " + format_double(*value) + " is not finite: a branch is followed between finite " +
                             p_name);
        }
    }
    if (!(*lo < *hi)) throw InputError(lo_key + " = " + format_double(*lo) + " is not below " + hi_key + " = " + format_double(*hi));
    if (p0 < *lo || p0 > *hi) {
        throw InputError("the start's " + p_name + " = " + format_double(p0) + p0_origin + " is outside " + lo_key + " " +
                         format_double(*lo) + " " + hi_key + " " + format_double(*hi));
    }
}

ContinuationRun::Curves resolve_curves(const ContinuationInput& in, const ContinuationRun& run, const KeySpelling& spell)
{
    const std::string key = spell("curve");
    const auto second = parameter_named(in.curve);
    if (!second) throw InputError(key + " = " + in.curve + " is not a coefficient: accepted " + parameter_list());
    if (!independent(run.parameter, *second)) {
        throw InputError(key + " = " + in.curve + " moves a coefficient " + spell("param") + " " + in.param +
                         " moves too: accepted a coefficient independent of it");
    }
    if (!parameter_defined(run.model, *second)) {
        throw InputError(key + " = " + in.curve + " sets both surfaces, but the wall's and the floor's " + in.curve +
                         " differ: use " + in.curve + "_wall or " + in.curve + "_floor");
    }
    check_bounds(*second, in.curve_min, in.curve_max, spell("curve_min"), spell("curve_max"), in.curve,
                 parameter_value(run.model, *second), "");
    if (!(in.curve_max_step > 0.0 && std::isfinite(in.curve_max_step))) {
        throw InputError(spell("curve_max_step") + " = " + format_double(in.curve_max_step) + " is out of range: accepted > 0");
    }
    if (!(in.curve_step > 1e-5 && in.curve_step <= in.curve_max_step)) {
        throw InputError(spell("curve_step") + " = " + format_double(in.curve_step) + " is out of range: accepted 1e-05 < " +
                         spell("curve_step") + " <= " + spell("curve_max_step"));
    }
    if (in.curve_max_points < 1) {
        throw InputError(spell("curve_max_points") + " = " + std::to_string(in.curve_max_points) +
                         " is out of range: accepted >= 1");
    }
    EventCurveSettings set;
    set.min1 = run.settings.min;
    set.max1 = run.settings.max;
    set.min2 = *in.curve_min;
    set.max2 = *in.curve_max;
    set.initial_step = in.curve_step;
    set.max_step = in.curve_max_step;
    set.max_points = in.curve_max_points;
    return {*second, set};
}

}  // namespace

std::string parameter_list()
{
    std::string s;
    for (const Parameter p : all_parameters) s += (s.empty() ? "" : ", ") + std::string(name(p));
    return s;
}

ContinuationRun resolve_continuation(const ContinuationInput& in, const KeySpelling& spell)
{
    constexpr double default_step = 0.01;
    ContinuationRun run;
    run.model = resolve_model(in.model, spell);
    const std::string param = spell("param");
    if (in.param.empty()) throw InputError(param + " is not set: give the coefficient to continue in, one of " + parameter_list());
    const auto parameter = parameter_named(in.param);
    if (!parameter) throw InputError(param + " = " + in.param + " is not a coefficient: accepted " + parameter_list());
    run.parameter = *parameter;
    if (!parameter_defined(run.model, run.parameter)) {
        throw InputError(param + " = " + in.param + " sets both surfaces, but the wall's and the floor's " + in.param +
                         " differ: continue in " + in.param + "_wall or " + in.param + "_floor");
    }
    check_bounds(run.parameter, in.min, in.max, spell("min"), spell("max"), in.param,
                 parameter_value(run.model, run.parameter), " (from the model)");
    check_cycle_search({in.period, in.starts, in.seed, in.corner}, spell);
    const std::string max_step = spell("max_step"), step_key = spell("step");
    if (!(in.max_step > 0.0 && std::isfinite(in.max_step))) {
        throw InputError(max_step + " = " + format_double(in.max_step) + " is out of range: accepted " + max_step + " > 0");
    }
    const double step = in.step.value_or(std::min(default_step, in.max_step));
    if (!(step > 0.0 && step <= in.max_step)) {
        throw InputError(step_key + " = " + format_double(step) + " is out of range: accepted 0 < " + step_key + " <= " +
                         max_step + " (" + format_double(in.max_step) + ")");
    }
    if (!(in.min_step > 0.0 && in.min_step <= step)) {
        throw InputError(spell("min_step") + " = " + format_double(in.min_step) + " is out of range: accepted 0 < " +
                         spell("min_step") + " <= " + step_key + " (" + format_double(step) + ")");
    }
    if (in.max_points < 1) {
        throw InputError(spell("max_points") + " = " + std::to_string(in.max_points) + " is out of range: accepted >= 1");
    }
    run.settings = {*in.min, *in.max, step, in.min_step, in.max_step, in.max_points};
    if (!in.curve.empty()) run.curves = resolve_curves(in, run, spell);
    if (in.start) {
        const CanonicalState<double>& s = *in.start;
        if (!(s.xi >= 0.0 && s.xi < 1.0 && s.U < 0.0 && std::isfinite(s.W))) {
            throw InputError(spell("start") + " = " + format_double(s.xi) + "," + format_double(s.U) + "," +
                             format_double(s.W) +
                             " is not a launch toward the wall: accepted 0 <= xi < 1 (0: the corner plane), U < 0");
        }
        run.start = s;
        run.start_key = spell("start");
    }
    run.period = in.period;
    run.search = {in.period, in.starts, in.seed, in.corner};
    return run;
}

ContinuationResult continue_branches(const ContinuationRun& run, const mpi::Comm& comm) { return continue_with(run, comm); }

ContinuationResult continue_branches(const ContinuationRun& run) { return continue_with(run, Alone{}); }

}  // namespace superball
