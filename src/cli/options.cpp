#include "options.hpp"

#include <memory>
#include <stdexcept>

namespace superball::cli {

std::string flag_spelling(std::string_view key)
{
    std::string s = "--";
    for (const char c : key) s += c == '_' ? '-' : c;
    return s;
}

void write_output(const std::string& path, const std::function<void(std::FILE*)>& write)
{
    if (path.empty()) {
        write(stdout);
        return;
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!file) throw std::runtime_error("cannot write " + path);
    write(file.get());
    if (std::fclose(file.release()) != 0) throw std::runtime_error("cannot write " + path);
}

Start resolve_start(const StartInput& in) { return superball::resolve_start(in, flag_spelling); }

}  // namespace superball::cli
