// superball serve: the explorer in a browser (serve/server.hpp).
#include <fmt/core.h>

#include <cstdio>

#include "serve_command.hpp"
#include "serve/server.hpp"

namespace superball::cli {

int serve_command(const ServeOptions& opt)
{
    serve::ServeSettings settings = opt.settings;
    settings.layers.assign(opt.layers.begin(), opt.layers.end());
    serve::serve(settings, [&](const std::string& url) {
        fmt::print("superball serve: {} (Ctrl-C to stop)\n", url);
        if (settings.host != "127.0.0.1" && settings.host != "localhost" && settings.host != "::1") {
            fmt::print(stderr, "superball serve: listening on {}: anyone who can reach it can use this server\n",
                       settings.host);
        }
        std::fflush(stdout);
    });
    return 0;
}

}  // namespace superball::cli
