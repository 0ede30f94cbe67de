// superball._core, the compiled half of the Python package `superball` (src/python/superball):
// argument conversion and one library call per function, nothing else. The package's
// __init__.py gives the documented API (broadcasting, defaults, docstrings, xarray).
//
// Every library call that counts runs with the GIL released, so other Python threads run
// meanwhile. Bad input raises ValueError naming the argument (InputError of the library,
// whose messages spell keys as Python arguments here), a failed run RuntimeError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/count.hpp"
#include "core/input.hpp"
#include "core/kernels.hpp"
#include "core/report.hpp"
#include "core/trajectory.hpp"
#include "io/layout.hpp"
#include "io/result_reader.hpp"
#include "job/job.hpp"
#include "job/provenance.hpp"
#include "run/count_threads.hpp"
#include "run/explore_threads.hpp"
#include "cli/terminal_progress.hpp"
#include "bindings.hpp"
#include "superball/version.hpp"

namespace py = pybind11;

namespace superball {
namespace {

const KernelVariant& kernel_of(const std::string& name)
{
    return name.empty() ? select_kernel({}) : kernel_named(name, "kernel = '" + name + "'");
}

// One start coordinate: a NumPy array of float64 or float32 (the package converts other
// real types), any strides (broadcast views repeat values with stride 0), read a block
// of points at a time in C order by the counting threads.
class CoordinateArray {
public:
    CoordinateArray(std::string name, const py::array& a) : name_(std::move(name)), array_(a)
    {
        const py::dtype t = a.dtype();
        // Native byte order only: the package swaps any other (a '>f8' array read as it is
        // gave wrong counts without a word).
        // (NumPy's descriptor may spell the native order '<' as well as '=': h5py's arrays do.)
        const char native = std::endian::native == std::endian::little ? '<' : '>';
        const bool native_order = t.byteorder() == '=' || t.byteorder() == native;
        if (t.kind() != 'f' || (t.itemsize() != 8 && t.itemsize() != 4) || !native_order) {
            throw py::type_error(name_ + ": a float64 or float32 array in native byte order is expected here");
        }
        f32_ = t.itemsize() == 4;
        data_ = static_cast<const char*>(a.data());
        // The kernel reads a contiguous float64 array in place, as doubles: only when they are
        // aligned (a view into a byte buffer may not be; gather() copies those).
        aligned_ = reinterpret_cast<std::uintptr_t>(a.data()) % alignof(double) == 0;
        shape_.assign(a.shape(), a.shape() + a.ndim());
        strides_.assign(a.strides(), a.strides() + a.ndim());
        py::ssize_t expected = static_cast<py::ssize_t>(t.itemsize());
        contiguous_ = !f32_ && aligned_;
        for (std::size_t k = shape_.size(); k-- > 0;) {
            if (shape_[k] != 1 && strides_[k] != expected) contiguous_ = false;
            expected *= shape_[k];
        }
    }

    const std::vector<py::ssize_t>& shape() const { return shape_; }

    // The values themselves when they lie as float64 one after the other (no copy needed).
    const double* contiguous() const { return contiguous_ ? static_cast<const double*>(array_.data()) : nullptr; }

    // Values [first, first + n) as doubles into out.
    void read(std::size_t first, std::size_t n, double* out) const
    {
        if (f32_) {
            gather<float>(first, n, out);
        } else {
            gather<double>(first, n, out);
        }
    }

    // InputError naming the coordinate, the value and its index at the first value of
    // `values` (points first, first + 1, ...) that is not finite.
    void check_finite(std::size_t first, std::span<const double> values) const
    {
        for (std::size_t i = 0; i < values.size(); ++i) {
            if (!std::isfinite(values[i])) {
                throw InputError(name_ + " = " + format_double(values[i]) + " at index " + index_text(first + i) +
                                 " is not a finite number: accepted finite values (those that are no launch toward the "
                                 "wall count as outcome invalid)");
            }
        }
    }

private:
    template <class T>
    void gather(std::size_t first, std::size_t n, double* out) const
    {
        const std::size_t d = shape_.size();
        const auto load = [](const char* p) {
            T v;
            std::memcpy(&v, p, sizeof v);  // NumPy arrays may be unaligned
            return static_cast<double>(v);
        };
        if (d == 0) {
            for (std::size_t i = 0; i < n; ++i) out[i] = load(data_);
            return;
        }
        std::vector<py::ssize_t> index(d);
        std::size_t rest = first;
        const char* p = data_;
        for (std::size_t k = d; k-- > 0;) {
            index[k] = static_cast<py::ssize_t>(rest % static_cast<std::size_t>(shape_[k]));
            rest /= static_cast<std::size_t>(shape_[k]);
            p += index[k] * strides_[k];
        }
        const py::ssize_t last = shape_[d - 1], step = strides_[d - 1];
        std::size_t i = 0;
        for (;;) {
            for (; index[d - 1] < last && i < n; ++index[d - 1], ++i, p += step) out[i] = load(p);
            if (i == n) return;
            // The next row: carry into the axes before the last.
            p -= last * step;
            index[d - 1] = 0;
            for (std::size_t k = d - 1; k-- > 0;) {
                p += strides_[k];
                if (++index[k] < shape_[k]) break;
                p -= shape_[k] * strides_[k];
                index[k] = 0;
            }
        }
    }

    std::string index_text(std::size_t flat) const
    {
        std::vector<std::size_t> index(shape_.size());
        for (std::size_t k = shape_.size(); k-- > 0;) {
            index[k] = flat % static_cast<std::size_t>(shape_[k]);
            flat /= static_cast<std::size_t>(shape_[k]);
        }
        std::string s = "(";
        for (std::size_t k = 0; k < index.size(); ++k) s += (k ? ", " : "") + std::to_string(index[k]);
        return s + (index.size() == 1 ? ",)" : ")");
    }

    std::string name_;
    py::array array_;  // keeps the data alive
    const char* data_ = nullptr;
    std::vector<py::ssize_t> shape_, strides_;
    bool f32_ = false;
    bool aligned_ = false;
    bool contiguous_ = false;
};

// InputError for the first point (in C order) with a coordinate that is not finite, naming
// the coordinate, the value and the index. The kernel counts a launch with a non-finite
// coordinate as invalid (and a physical start that is no launch becomes NaN), so only the
// invalid points are looked at, found by memchr: checking every coordinate of every point
// before counting cost count() 15 % of its time on 4e6 launches (perf, check_finite).
void refuse_non_finite(const std::vector<CoordinateArray>& c, std::span<const std::uint8_t> outcomes)
{
    static_assert(static_cast<int>(Outcome::invalid) == 0);
    const std::uint8_t* const begin = outcomes.data();
    const std::uint8_t* const end = begin + outcomes.size();
    for (const std::uint8_t* p = begin; p != end; ++p) {
        p = static_cast<const std::uint8_t*>(std::memchr(p, 0, static_cast<std::size_t>(end - p)));
        if (p == nullptr) return;
        const auto i = static_cast<std::size_t>(p - begin);
        for (const CoordinateArray& a : c) {
            double v = 0;
            a.read(i, 1, &v);
            a.check_finite(i, {&v, 1});
        }
    }
}

// resolve_one_start(): what count() and trajectory() check first, as the command line does
// (core/input.hpp): `given` names the start's coordinates that are set (arrays or numbers:
// only which ones matters here). Returns (physical, g, radius, max_bounces).
py::tuple one_start(const std::vector<std::string>& given, std::optional<double> g, std::optional<double> radius,
                    const std::string& max_bounces, const ModelInput& model)
{
    StartInput in;
    in.g = g;
    in.radius = radius;
    std::optional<double>* const slots[] = {&in.xi, &in.U, &in.W, &in.x, &in.u, &in.v, &in.omega};
    const std::string_view names[] = {"xi", "U", "W", "x", "u", "v", "omega"};
    for (const std::string& name : given) {
        const auto at = std::find(std::begin(names), std::end(names), name);
        if (at == std::end(names)) throw std::invalid_argument("resolve_one_start: no coordinate " + name);
        *slots[at - std::begin(names)] = 0.0;
    }
    const OneStartSetup s = resolve_one_start(model, in, max_bounces, python_key);
    return py::make_tuple(s.start.physical, s.start.frame.g, s.start.frame.radius, s.max_bounces);
}

// count(): the package has checked the input (one_start), broadcast the coordinates to one
// shape (NumPy views) and checked the scalars' types. Returns (wall_bounces uint32,
// outcome uint8) of that shape.
py::tuple count_arrays(const std::vector<std::pair<std::string, py::array>>& coordinates, bool physical, double g,
                       double radius, const ModelInput& given, std::uint32_t max_bounces, unsigned threads,
                       const std::string& kernel)
{
    const Model model = resolve_model(given, python_key);
    const CountKernel k = kernel_of(kernel).count;
    std::vector<CoordinateArray> c;
    for (const auto& [name, a] : coordinates) c.emplace_back(name, a);
    if (c.size() != (physical ? 4u : 3u)) throw std::invalid_argument("count: wrong number of coordinates");
    const std::vector<py::ssize_t> shape = c.front().shape();
    std::size_t n = 1;
    for (const py::ssize_t s : shape) n *= static_cast<std::size_t>(s);
    py::array_t<std::uint32_t> wall_bounces(shape);
    py::array_t<std::uint8_t> outcomes(shape);
    const std::span<std::uint32_t> wb(wall_bounces.mutable_data(), n);
    const std::span<std::uint8_t> oc(outcomes.mutable_data(), n);
    const bool in_place = !physical && c[0].contiguous() && c[1].contiguous() && c[2].contiguous();
    const LoadStarts load = [&](std::size_t first, std::size_t count, Starts& buffer) -> StartsView {
        if (in_place) {
            return StartsView{{c[0].contiguous() + first, count}, {c[1].contiguous() + first, count},
                              {c[2].contiguous() + first, count}};
        }
        buffer.resize(count);
        std::vector<double>* columns[] = {&buffer.xi, &buffer.U, &buffer.W};
        for (std::size_t k = 0; k < 3; ++k) c[k].read(first, count, columns[k]->data());
        if (physical) {
            std::vector<double> omega(count);
            c[3].read(first, count, omega.data());
            for (std::size_t i = 0; i < count; ++i) {
                buffer.set(i, canonical_launch({buffer.xi[i], buffer.U[i], buffer.W[i], omega[i] * radius}, g));
            }
        }
        return buffer.view();
    };
    {
        const py::gil_scoped_release release;
        count_on_threads(load, ModelMatrices::of(model), max_bounces, wb, oc, {k, threads});
        refuse_non_finite(c, oc);
    }
    return py::make_tuple(wall_bounces, outcomes);
}

template <class T>
py::array_t<T> column(const std::vector<TrajectoryRow>& rows, T TrajectoryRow::*member)
{
    py::array_t<T> a(static_cast<py::ssize_t>(rows.size()));
    T* out = a.mutable_data();
    for (const TrajectoryRow& r : rows) *out++ = r.*member;
    return a;
}

// trajectory(): (columns as the CLI's CSV, what the launch came to).
py::tuple trajectory_table(const StartInput& in, const ModelInput& given, std::uint32_t max_bounces, int samples)
{
    const Model model = resolve_model(given, python_key);
    const Start start = resolve_start(in, python_key);
    if (samples != 0 && (samples < 2 || samples > 100000)) {
        throw InputError("samples = " + std::to_string(samples) + " is out of range: accepted 0 or 2..100000");
    }
    Trajectory tr;
    {
        const py::gil_scoped_release release;
        tr = trajectory(start.state, model, start.frame.g, max_bounces, samples);
    }
    const std::vector<TrajectoryRow> rows = trajectory_rows(tr, start.frame.radius);
    py::list events;
    for (const TrajectoryRow& r : rows) events.append(py::str(std::string(r.event)));
    py::dict columns;
    columns["event"] = events;
    columns["wall_bounces"] = column(rows, &TrajectoryRow::wall_bounces);
    const std::pair<const char*, double TrajectoryRow::*> doubles[] = {
        {"t", &TrajectoryRow::t},       {"x", &TrajectoryRow::x},   {"y", &TrajectoryRow::y},
        {"u_in", &TrajectoryRow::u_in}, {"v_in", &TrajectoryRow::v_in}, {"omega_in", &TrajectoryRow::omega_in},
        {"u", &TrajectoryRow::u},       {"v", &TrajectoryRow::v},   {"omega", &TrajectoryRow::omega}};
    for (const auto& [key, member] : doubles) columns[key] = column(rows, member);
    py::list contacts;
    for (const TrajectoryRow& r : rows) contacts.append(py::str(std::string(r.contact)));
    columns["contact"] = contacts;
    columns["beta"] = column(rows, &TrajectoryRow::beta);
    py::dict result;
    result["wall_bounces"] = tr.result.wall_bounces;
    result["outcome"] = std::string(name(tr.result.outcome));
    result["truncated"] = tr.truncated;
    result["units"] = start.physical ? "SI" : "dimensionless (v0 = g = radius = 1)";
    result["g"] = start.frame.g;
    result["radius"] = start.frame.radius;
    result["start"] = py::make_tuple(start.canonical.xi, start.canonical.U, start.canonical.W);
    return py::make_tuple(columns, result);
}

py::dict job_dict(const Job& job)
{
    py::dict d;
    d["text"] = job.text;
    d["output"] = job.output;
    d["points"] = job.points();
    return d;
}

// explore(): runs the job on threads (GIL released); Ctrl-C stops it cleanly (the partial
// file is kept, resumable) and raises KeyboardInterrupt.
// `run`: as the package passes it, output, overwrite, resume, threads, kernel, command and
// progress.
py::dict explore(const std::string& text, const std::string& source, const py::dict& run)
{
    const Job job = parse_job(text, source);
    ExploreSettings settings;
    settings.output = run["output"].cast<std::string>();
    settings.overwrite = run["overwrite"].cast<bool>();
    settings.resume = run["resume"].cast<bool>();
    settings.kernel = kernel_of(run["kernel"].cast<std::string>()).count;
    settings.command = run["command"].cast<std::string>();
    const auto threads = run["threads"].cast<unsigned>();
    TerminalProgress observer(stderr, !run["progress"].cast<bool>());
    std::optional<py::error_already_set> interrupt;
    // Polled on this (the calling) thread between its tiles: Python runs signal handlers on
    // its main thread only, and only when asked.
    const StopRequested stop = [&] {
        if (interrupt) return true;
        const py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) interrupt.emplace();
        return interrupt.has_value();
    };
    RunSummary r;
    {
        const py::gil_scoped_release release;
        r = run_explore_threads(job, settings, threads, observer, stop);
    }
    if (interrupt) throw *interrupt;
    py::dict d;
    d["output"] = r.output.string();
    d["complete"] = r.complete;
    d["interrupted"] = r.interrupted;
    d["nothing_to_do"] = r.nothing_to_do;
    d["points_this_run"] = r.points_this_run;
    d["points_counted"] = r.points_counted;
    py::dict outcomes;
    for (int o = 0; o < outcome_count; ++o) outcomes[py::str(std::string(name(static_cast<Outcome>(o))))] = r.outcomes[static_cast<std::size_t>(o)];
    d["outcomes"] = outcomes;
    d["compute_seconds"] = r.compute_seconds;
    d["finish_seconds"] = r.finish_seconds;
    d["raw_bytes"] = r.raw_bytes;
    d["result_bytes"] = r.result_bytes;
    d["sidecar"] = r.sidecar_note;
    d["peak_rss_mib"] = r.peak_rss_mib;
    d["kernel"] = describe(settings.kernel);
    return d;
}

// open(): the validation `superball info` makes (structure, then every value); a partial
// file (a run not finished) is refused. Returns what the file says about itself.
py::dict validate(const std::string& path)
{
    std::error_code ec;
    if (!std::filesystem::exists(path, ec) && std::filesystem::exists(layout::partial_path(path), ec)) {
        throw FormatError(path + " does not exist yet: its run is not finished (" + layout::partial_path(path).string() +
                          " holds it); finish it with superball explore JOB --resume or superball.explore(JOB, resume=True)");
    }
    OutcomeCounts counts;
    ResultInfo info;
    {
        const py::gil_scoped_release release;
        const ResultReader reader(path);
        info = reader.info();
        if (info.kind != FileKind::result) {
            throw FormatError(path + " is the partial file of a run not finished (" + std::to_string(info.tiles_done) + " of " +
                              std::to_string(info.tiles) + " tiles done), not a result: finish it with superball explore "
                              "JOB --resume or superball.explore(JOB, resume=True)");
        }
        counts = reader.outcome_counts();
    }
    py::dict d;
    // Keyed as the file's attributes are.
    namespace attr = layout::attr;
    d[attr::coordinate_system.name] = info.coordinate_system;
    d[attr::axis_names.name] = info.axis_names;
    d["shape"] = info.shape;
    d[attr::max_bounces.name] = info.max_bounces;
    d[attr::software_version.name] = info.software_version;
    d[attr::history.name] = info.history;
    d[attr::source.name] = info.source;
    d[attr::date_created.name] = info.date_created;
    py::dict outcomes;
    for (int o = 0; o < outcome_count; ++o) outcomes[py::str(std::string(name(static_cast<Outcome>(o))))] = counts.by_outcome[static_cast<std::size_t>(o)];
    d["outcomes"] = outcomes;
    return d;
}

}  // namespace
}  // namespace superball

PYBIND11_MODULE(_core, m)
{
    using namespace superball;
    m.doc() = "The compiled part of superball: use the package superball, which documents every function.";
    // InputError (and FormatError): bad input, naming the argument or the file.
    // NOLINTNEXTLINE(performance-unnecessary-value-param): pybind11 takes a void(*)(std::exception_ptr)
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });
    m.attr("version") = software_version;
    m.attr("source") = software_source();
    m.attr("build") = software_build();
    m.attr("kernel_report") = kernel_report();
    std::vector<std::string> outcomes;
    for (int o = 0; o < outcome_count; ++o) outcomes.emplace_back(name(static_cast<Outcome>(o)));
    m.attr("outcomes") = py::tuple(py::cast(outcomes));
    m.attr("usable_cores") = usable_cores();

    m.def(
        "resolve_one_start",
        [](const std::vector<std::string>& given, std::optional<double> g, std::optional<double> radius,
           const std::string& max_bounces, const ModelInput& model) {
            return one_start(given, g, radius, max_bounces, model);
        },
        py::arg("given"), py::arg("g"), py::arg("radius"), py::arg("max_bounces"), py::arg("model"));
    m.def("count", &count_arrays, py::arg("coordinates"), py::arg("physical"), py::arg("g"), py::arg("radius"),
          py::arg("model"), py::arg("max_bounces"), py::arg("threads"), py::arg("kernel"));
    m.def(
        "trajectory",
        [](std::optional<double> xi, std::optional<double> U, std::optional<double> W, std::optional<double> x,
           std::optional<double> u, std::optional<double> v, std::optional<double> omega, std::optional<double> g,
           std::optional<double> radius, const ModelInput& model, std::uint32_t max_bounces, int samples) {
            return trajectory_table({xi, U, W, x, u, v, omega, g, radius}, model, max_bounces, samples);
        },
        py::arg("xi"), py::arg("U"), py::arg("W"), py::arg("x"), py::arg("u"), py::arg("v"), py::arg("omega"), py::arg("g"),
        py::arg("radius"), py::arg("model"), py::arg("max_bounces"), py::arg("samples"));
    add_dynamics(m);
    m.def("parse_job", [](const std::string& text, const std::string& source) { return job_dict(parse_job(text, source)); },
          py::arg("text"), py::arg("source"));
    m.def("load_job", [](const std::string& path) { return job_dict(load_job(path)); }, py::arg("path"));
    m.def("explore", &explore, py::arg("text"), py::arg("source"), py::arg("run"));
    m.def("validate", &validate, py::arg("path"));
}
