// The schema of superball's files as the reader checks it (io/result_reader.hpp): the limits
// a sane file keeps, and Checker, which reads a root attribute or opens a dataset only after
// checking its type and shape, each refusal a FormatError naming the file and the object.
// Internal to io: result_schema.cpp validates a file's structure with it at open,
// result_reader.cpp its values as they are read.
#pragma once

#include <fmt/core.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "hdf5.hpp"
#include "job/job.hpp"
#include "job/tiles.hpp"
#include "result_reader.hpp"

namespace superball::schema {

// What a file may hold; beyond it the file is damaged, not big: a job's grid and max_bounces
// (max_grid_points, max_max_bounces: job/job.hpp), and texts (a job file is a few hundred
// bytes; names and versions a few).
inline constexpr std::size_t max_job_bytes = std::size_t{1} << 20;
inline constexpr std::size_t max_text_bytes = 4096;

// "a scalar", or the dimensions as "(40, 30)".
std::string dims_text(const std::vector<hsize_t>& dims);
// What an attribute or dataset holds, for messages: "a text", "a list of 2 integers", ...
std::string shape_text(const h5::Shape& s);
// Opens `path` read-only, saying what it is when it is not HDF5 at all (FormatError).
h5::Id open_hdf5(const std::filesystem::path& path);
// The byte ranges of the file's big raw data, which h5::damaged_global_heap need not search.
std::vector<std::pair<std::uint64_t, std::uint64_t>> raw_data_ranges(hid_t file);

class Checker {
public:
    Checker(hid_t file, const std::filesystem::path& path) : file_(file), path_(path.string()) {}

    [[noreturn]] void fail(const std::string& what) const { throw FormatError(path_ + ": " + what); }

    // Root attributes of the kinds the format uses, each checked for its type and shape
    // before it is read.
    std::string text(const std::string& name, std::size_t max_bytes = max_text_bytes) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::string || !s.scalar) fail("attribute " + name + " is " + shape_text(s) + ", not a text");
        if (!s.variable_length && s.bytes > max_bytes) too_long(name, s.bytes, max_bytes);
        std::string v = h5::read_string_attribute(file_, name);
        if (v.size() > max_bytes) too_long(name, v.size(), max_bytes);
        return v;
    }
    std::int64_t integer(const std::string& name, std::int64_t lo, std::int64_t hi) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::integer || !s.scalar) {
            fail("attribute " + name + " is " + shape_text(s) + ", not an integer");
        }
        const std::int64_t v = h5::read_int_attribute(file_, name);
        if (v < lo || v > hi) fail(fmt::format("attribute {} = {} is out of range: accepted {} to {}", name, v, lo, hi));
        return v;
    }
    double number(const std::string& name) const
    {
        const h5::Shape s = shape(name);
        if ((s.type != h5::TypeClass::floating && s.type != h5::TypeClass::integer) || !s.scalar) {
            fail("attribute " + name + " is " + shape_text(s) + ", not a number");
        }
        const double v = h5::read_double_attribute(file_, name);
        if (!std::isfinite(v)) fail(fmt::format("attribute {} = {} is not finite", name, v));
        return v;
    }
    std::vector<std::string> texts(const std::string& name, std::size_t max_items) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::string || s.dims.size() != 1) {
            fail("attribute " + name + " is " + shape_text(s) + ", not a list of texts");
        }
        if (s.dims[0] < 1 || s.dims[0] > max_items) {
            fail(fmt::format("attribute {} lists {} items: accepted 1 to {}", name, s.dims[0], max_items));
        }
        if (!s.variable_length && s.bytes > max_text_bytes) too_long(name, s.bytes, max_text_bytes);
        std::vector<std::string> v = h5::read_string_vector_attribute(file_, name);
        for (const std::string& t : v) {
            if (t.size() > max_text_bytes) too_long(name, t.size(), max_text_bytes);
        }
        return v;
    }
    std::vector<std::uint64_t> integers(const std::string& name, std::size_t items) const
    {
        const h5::Shape s = shape(name);
        if (s.type != h5::TypeClass::integer || s.dims.size() != 1) {
            fail("attribute " + name + " is " + shape_text(s) + ", not a list of integers");
        }
        if (s.dims[0] != items) fail(fmt::format("attribute {} lists {} integers for {} dimensions", name, s.dims[0], items));
        return h5::read_u64_vector_attribute(file_, name);
    }

    h5::Id dataset(const std::string& name) const
    {
        if (h5::object_type(file_, name) != h5::ObjectType::dataset) fail(name + " is missing or not a dataset");
        return h5::open_dataset(file_, name);
    }

    // The data of `name` are all stored (a chunk never written would read as zeros).
    void allocated(hid_t d, const std::string& name) const
    {
        if (!h5::dataset_storage(d).allocated) fail(name + " lacks storage for part of its data: the file is incomplete or damaged");
    }

private:
    h5::Shape shape(const std::string& name) const
    {
        const std::optional<h5::Shape> s = h5::attribute_shape(file_, name);
        if (!s) fail("attribute " + name + " is missing");
        return *s;
    }
    [[noreturn]] void too_long(const std::string& name, std::size_t bytes, std::size_t max) const
    {
        fail(fmt::format("attribute {} holds a text of {} bytes: accepted at most {}", name, bytes, max));
    }

    hid_t file_;
    std::string path_;
};

}  // namespace superball::schema
