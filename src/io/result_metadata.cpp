#include "result_metadata.hpp"

#include <string>

#include "hdf5.hpp"
#include "layout.hpp"
#include "superball/version.hpp"

namespace superball {

namespace {

namespace attr = layout::attr;

// An attribute of the schema (io/layout.hpp), written with the type it states.
template <class T>
void put(hid_t obj, layout::Attribute<T> a, const std::type_identity_t<T>& value)
{
    h5::write_attribute(obj, a.name, value);
}
void put(hid_t obj, layout::Attribute<layout::Text> a, const std::string& value) { h5::write_text_attribute(obj, a.name, value); }

void describe_variable(hid_t d, const std::string& name)
{
    const layout::VariableText t = layout::variable_text(name);
    put(d, attr::long_name, std::string(t.long_name));
    put(d, attr::units, std::string(t.units));
}

// A small contiguous float64 dataset, its space allocated at creation (parallel files
// require it of datasets written independently).
h5::Id create_doubles(hid_t file, const std::string& name, const std::vector<hsize_t>& dims)
{
    return h5::create_dataset(file, name, H5T_IEEE_F64LE, dims, {});
}

}  // namespace

hid_t count_type(const Job& job) { return job.max_bounces > 65535 ? H5T_STD_U32LE : H5T_STD_U16LE; }

std::size_t count_bytes(const Job& job) { return h5::type_size(count_type(job)); }

ResultInfo result_info(const Job& job, const Grid& grid)
{
    ResultInfo info;
    info.kind = FileKind::result;
    info.coordinate_system = name(job.coordinates);
    for (const Coordinate* c : job.range_axes()) info.axis_names.push_back(c->name);
    for (const Coordinate& c : job.grid) {
        if (!c.is_range()) info.fixed.emplace_back(c.name, *c.fixed);
    }
    info.shape = grid.shape();
    info.count_bytes = count_bytes(job);
    info.job_toml = job.text;
    info.job_fingerprint = fingerprint(job);
    info.software_version = software_version;
    info.max_bounces = job.max_bounces;
    info.complete = true;
    return info;
}

std::vector<h5::Id> write_metadata(hid_t file, const Job& job, const Grid& grid, const char* kind, const RunFigures& run,
                                   bool write_samples)
{
    std::vector<h5::Id> axes;
    std::vector<std::string> axis_names;
    const std::vector<const Coordinate*> ranges = job.range_axes();
    for (std::size_t k = 0; k < ranges.size(); ++k) {
        const std::string& name = ranges[k]->name;
        axis_names.push_back(name);
        const std::vector<double>& s = grid.samples(k);
        h5::Id d = create_doubles(file, "/" + name, {s.size()});
        if (write_samples) {
            h5::write(d, std::span(s), "/" + name);
        }
        describe_variable(d, name);
        h5::make_dimension_scale(d, name);
        axes.push_back(std::move(d));
    }
    // No /axes/<name> (the layout of superball 0.1): links there show up in netCDF tools as
    // a group of duplicate dimensions.
    for (const Coordinate& c : job.grid) {
        if (c.is_range()) continue;
        const h5::Id d = create_doubles(file, "/" + c.name, {});
        if (write_samples) {
            h5::write(d, std::span<const double>(&*c.fixed, 1), "/" + c.name);
        }
        describe_variable(d, c.name);
        h5::write_attribute(file, attr::fixed_prefix + c.name, *c.fixed);
    }

    put(file, attr::kind, kind);
    put(file, attr::format, layout::format_version);
    put(file, attr::conventions, "CF-1.8");
    put(file, attr::title, "superball: wall bounces of a superball between a floor and a wall, over a grid of launches");
    // Provenance (CF and ACDD): the software and the run that created the file; history
    // (write_run_figures) has a line per run.
    put(file, attr::source, software_source());
    put(file, attr::date_created, run.run.date);
    put(file, attr::build, software_build() + (run.run.kernel.empty() ? "" : "; counting kernel " + run.run.kernel));
    // Not "coordinates": that is CF's keyword for auxiliary coordinates, which xarray takes.
    put(file, attr::coordinate_system, std::string(name(job.coordinates)));
    put(file, attr::axis_names, axis_names);
    // A swept coefficient has no single value: its attribute names the axis instead
    // ("axis:e"), and `swept` lists the coefficient axes.
    // Every coefficient; SPEC.md 1b's (mu_wall, mu_floor, inertia) where not their defaults,
    // so that a file of the Cross model of a solid ball is what it was before them (and no
    // attribute is infinite: readers take a missing one as the default).
    const std::vector<std::string> keys = model_coefficient_names();
    const std::array<double, swept_coefficients> values = model_coefficients(job.model);
    const std::array<double, swept_coefficients> defaults = model_coefficients(Model{});
    for (std::size_t c = 0; c < swept_coefficients; ++c) {
        const std::string& key = keys[c];
        const double value = values[c];
        if (is_friction_coefficient(key) && job.swept[c] < 0 && value == defaults[c]) continue;
        if (job.swept[c] < 0) {
            h5::write_attribute(file, key, value);
        } else {
            h5::write_attribute(file, key, "axis:" + job.parameters[static_cast<std::size_t>(job.swept[c])].name);
        }
    }
    if (!job.parameters.empty()) {
        std::vector<std::string> swept;
        for (const Coordinate& p : job.parameters) swept.push_back(p.name);
        put(file, attr::swept, swept);
    }
    if (job.coordinates == Coordinates::physical) {
        put(file, attr::g, job.frame.g);
        put(file, attr::radius, job.frame.radius);
    }
    put(file, attr::max_bounces, job.max_bounces);
    // 0: every point computed; s: adaptive refinement from every s-th point.
    put(file, attr::refine, job.refine);
    put(file, attr::job_toml, job.text);
    put(file, attr::job_fingerprint, fingerprint(job));
    put(file, attr::software_version, std::string(software_version));
    write_run_figures(file, run);
    return axes;
}

void describe_data(hid_t wall_bounces, hid_t outcome, const Job& job, const std::vector<h5::Id>& axes)
{
    put(wall_bounces, attr::long_name, "wall impacts before the motion ended, or max_bounces (capped)");
    put(wall_bounces, attr::units, "1");
    put(outcome, attr::long_name, "how the motion ended");
    h5::write_attribute(outcome, attr::flag_values.name, std::span<const std::uint8_t>(layout::outcome_codes));
    put(outcome, attr::flag_meanings, layout::outcome_meanings);
    std::string fixed;
    for (const Coordinate& c : job.grid) {
        if (!c.is_range()) fixed += (fixed.empty() ? "" : " ") + c.name;
    }
    for (const hid_t d : {wall_bounces, outcome}) {
        if (!fixed.empty()) put(d, attr::coordinates, fixed);
        for (std::size_t k = 0; k < axes.size(); ++k) h5::attach_dimension_scale(d, axes[k], static_cast<unsigned>(k));
    }
}

void write_run_figures(hid_t file, const RunFigures& run)
{
    const std::string before = h5::has_attribute(file, attr::history) ? h5::read_string_attribute(file, attr::history) : "";
    // UTF-8 (a command line may name any path), as job_toml.
    put(file, attr::history, append_history(before, history_line(run.run)));
    put(file, attr::mpi_ranks, run.run.mpi_ranks);
    put(file, attr::mpi_hosts, run.run.hosts);
    put(file, attr::threads, run.run.threads);
    put(file, attr::wall_seconds, run.wall_seconds);
    put(file, attr::complete, run.complete ? 1 : 0);
}

}  // namespace superball
