// superball serve: the explorer in a browser (serve/server.hpp).
#include <fmt/core.h>

#include <cstdio>
#include <memory>

#include "commands.hpp"
#include "serve/server.hpp"

namespace superball::cli {

namespace {
struct ServeOptions {
    std::vector<std::string> layers;
    serve::ServeSettings settings;
};
}  // namespace

Runner add_serve_command(CLI::App& app)
{
    auto* sub = app.add_subcommand("serve", "Explore the regions in a browser: an HTTP server with a deep-zoom map");
    sub->footer(
        "Serves a page with a deep-zoom map of wall-bounce counts (or outcomes) over two canonical axes, computed\n"
        "on demand at the zoom's resolution, the trajectory of a clicked launch, and \"export this view\" as a\n"
        "job file; and the JSON API behind it (/api/count, /api/region, /api/trajectory, /api/job; docs/commands.md).\n"
        "Result files given as arguments open as layers. Binds to 127.0.0.1 (this machine only) unless --host\n"
        "says otherwise; prints the URL and serves until Ctrl-C or SIGTERM.");
    auto opt = std::make_shared<ServeOptions>();
    serve::ServeSettings& s = opt->settings;
    sub->add_option("results", opt->layers, "result files (.h5, or a partial file) to show as layers")->check(CLI::ExistingFile);
    sub->add_option("--host", s.host, "address to listen on (0.0.0.0: every interface; anyone who reaches it can use it)")
        ->capture_default_str();
    sub->add_option("--port", s.port, "port (0: any free port)")->check(CLI::Range(0, 65535))->capture_default_str();
    sub->add_option("--threads", s.threads, "counting threads (default: one per core)")->check(CLI::Range(1u, 1024u));
    sub->add_option("--time-limit", s.time_limit, "seconds a request may compute before it is refused (HTTP 503)")
        ->check(CLI::Range(0.001, 86400.0))
        ->capture_default_str();
    return [opt] {
        opt->settings.layers.assign(opt->layers.begin(), opt->layers.end());
        serve::serve(opt->settings, [&](const std::string& url) {
            fmt::print("superball serve: {} (Ctrl-C to stop)\n", url);
            if (opt->settings.host != "127.0.0.1" && opt->settings.host != "localhost" && opt->settings.host != "::1") {
                fmt::print(stderr, "superball serve: listening on {}: anyone who can reach it can use this server\n",
                           opt->settings.host);
            }
            std::fflush(stdout);
        });
        return 0;
    };
}

}  // namespace superball::cli
