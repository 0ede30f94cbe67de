// superball serve: an HTTP server for exploring the regions in a browser. It serves the
// page (web/, built into the binary, and Debian's Leaflet), map tiles computed on demand
// at the zoom's resolution, and the JSON API the page uses (docs/commands.md: Exploring
// in a browser, The API): /api/count, /api/region, /api/trajectory, /api/job, /api/legend, /api/info.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "view.hpp"

namespace superball::serve {

struct ServeSettings {
    std::vector<std::filesystem::path> layers;  // result files shown as layers
    std::string host = "127.0.0.1";
    int port = 8080;           // 0: any free port
    unsigned threads = 0;      // counting threads; 0: one per core this process may use
    double time_limit = 10.0;  // seconds a request may compute before it is refused (503)
    Limits limits{};
};

// Where Leaflet is installed (Debian's libjs-leaflet): the server serves it from there.
std::filesystem::path leaflet_directory();

// Opens the layers, binds to host:port, calls ready(url) and serves until SIGINT or
// SIGTERM, then returns. SIGPIPE, SIGINT and SIGTERM are blocked in the calling thread
// (and so in every thread it starts): the calling thread should be the program's only one.
// Throws InputError for a layer that cannot be shown or settings out of range,
// std::runtime_error when the address cannot be bound.
void serve(const ServeSettings& settings, const std::function<void(const std::string& url)>& ready);

}  // namespace superball::serve
