// A scratch directory for a C++ test, removed with everything in it when the test ends.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace superball::test_support {

class TempDir {
public:
    // Under the system's temporary directory, named PREFIX-XXXXXX.
    explicit TempDir(const std::string& prefix)
    {
        std::string t = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
        if (!mkdtemp(t.data())) throw std::runtime_error("mkdtemp " + t + " failed");
        path_ = t;
    }
    ~TempDir()
    {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

}  // namespace superball::test_support
