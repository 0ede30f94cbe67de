#include "server.hpp"

#include <arpa/inet.h>
#include <httplib.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "core/kernels.hpp"
#include "job/result_json.hpp"
#include "core/trajectory.hpp"
#include "job/provenance.hpp"
#include "layers.hpp"
#include "pool.hpp"
#include "region.hpp"
#include "superball/version.hpp"
#include "tiles.hpp"
#include "web_assets.hpp"

namespace superball::serve {

namespace fs = std::filesystem;

std::filesystem::path leaflet_directory() { return SUPERBALL_LEAFLET_DIR; }

namespace {

// Threads that carry connections (cpp-httplib gives each connection one thread while it
// lives, idle keep-alive time included): enough for several browsers' six connections
// and the load test's 16 clients; they only wait while the pool counts.
constexpr std::size_t connection_threads = 64;
// Tasks that may wait for a counting thread before requests are refused (503).
constexpr std::size_t max_pending_tasks = 256;
// How often a waiting request looks whether its client is still there.
constexpr std::chrono::milliseconds watch_interval{20};
constexpr std::uint64_t tile_size = 256;

// The client left: nothing to answer.
struct ClientGone {};

std::string address_text(const sockaddr_storage& a)
{
    char buf[INET6_ADDRSTRLEN] = "";
    if (a.ss_family == AF_INET) {
        inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in&>(a).sin_addr, buf, sizeof buf);
    } else if (a.ss_family == AF_INET6) {
        inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6&>(a).sin6_addr, buf, sizeof buf);
    }
    return buf;
}

int port_of(const sockaddr_storage& a)
{
    if (a.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in&>(a).sin_port);
    if (a.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6&>(a).sin6_port);
    return -1;
}

// Whether a request's client is still connected. cpp-httplib 0.11 does not hand the
// connection's socket to handlers: it is the descriptor of this process whose local port,
// remote port and remote address are the request's (a TCP connection is unique by them),
// looked up once, when a request has been waiting for its first interval.
class ClientWatch {
public:
    explicit ClientWatch(const httplib::Request& req) : req_(req) {}

    bool gone()
    {
        if (fd_ == not_looked_up) fd_ = find();
        if (fd_ < 0) return false;
        pollfd p{fd_, POLLIN | POLLRDHUP, 0};
        // An orderly close (the browser dropped a tile it no longer needs) or a reset.
        return poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) != 0;
    }

private:
    int find() const
    {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator("/proc/self/fd", ec)) {
            int fd = -1;
            const std::string name = entry.path().filename().string();
            if (std::from_chars(name.data(), name.data() + name.size(), fd).ec != std::errc()) continue;
            sockaddr_storage local{}, peer{};
            socklen_t n = sizeof local, m = sizeof peer;
            if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &n) != 0) continue;
            if (getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &m) != 0) continue;
            if (port_of(local) == req_.local_port && port_of(peer) == req_.remote_port &&
                address_text(peer) == req_.remote_addr) {
                return fd;
            }
        }
        return -1;
    }

    static constexpr int not_looked_up = -2;
    const httplib::Request& req_;
    int fd_ = not_looked_up;  // -1: not found
};

// cpp-httplib 0.11 as Debian built it listens with a backlog of 5 connections
// (CPPHTTPLIB_LISTEN_BACKLOG is fixed in its compiled library): with more clients
// connecting at once the kernel dropped connections, which came back a second later (the
// load test's p99 was 1 s). listen() again on the bound socket sets a longer backlog.
class HttpServer : public httplib::Server {
public:
    bool set_backlog(int connections) { return ::listen(svr_sock_, connections) == 0; }
};

constexpr int listen_backlog = 512;

void answer_json(httplib::Response& res, int status, const std::string& body)
{
    res.status = status;
    res.set_content(body, "application/json");
}

void answer_error(httplib::Response& res, int status, const std::string& message)
{
    answer_json(res, status, nlohmann::ordered_json{{"error", message}}.dump() + "\n");
}

// The region's header through nlohmann-json, its arrays by hand: built and dumped by
// nlohmann-json, the 2^20 points of the largest region took 70 ms against 16.5 ms (a
// benchmark of both on this machine, 2026-11-27, 3 runs each within 10 %).
std::string region_json(const View& v, const RegionCounts& r)
{
    const auto name = [](int k) { return std::string(axis_names[static_cast<std::size_t>(k)]); };
    nlohmann::ordered_json head = {{"x_axis", name(v.plane.x)},
                                   {"y_axis", name(v.plane.y)},
                                   {"fixed", {{name(v.plane.fixed), v.fixed}}},
                                   {"model", model_json(v.model)},
                                   {"max_bounces", v.max_bounces}};
    std::string out = head.dump();
    out.back() = ',';  // the object goes on with the arrays
    out += "\n";
    out.reserve(out.size() + r.nx * r.ny * 8 + (r.nx + r.ny) * 24);
    for (const auto& [key, range] : {std::pair{"x", &v.x}, std::pair{"y", &v.y}}) {
        out += " \"";
        out += key;
        out += "\": [";
        for (std::uint64_t i = 0; i < range->n; ++i) {
            out += i ? ", " : "";
            out += format_double(range->sample(i));
        }
        out += "],\n";
    }
    char buf[16];
    const auto rows = [&](auto value) {
        out += "[";
        for (std::uint64_t j = 0; j < r.ny; ++j) {
            out += j ? ",\n  [" : "\n  [";
            for (std::uint64_t i = 0; i < r.nx; ++i) {
                if (i) out += ',';
                const auto res = std::to_chars(buf, buf + sizeof buf, value(j * r.nx + i));
                out.append(buf, res.ptr);
            }
            out += "]";
        }
        out += "]";
    };
    out += " \"wall_bounces\": ";
    rows([&](std::uint64_t k) { return r.wall_bounces[k]; });
    out += ",\n \"outcome\": ";
    rows([&](std::uint64_t k) { return static_cast<unsigned>(r.outcomes[k]); });
    out += ",\n \"outcome_names\": [\"invalid\", \"left\", \"missed\", \"capped\"]}\n";
    return out;
}

// A Server-Timing header entry (milliseconds, as browsers' developer tools show them).
std::string timing(std::string_view name, Clock::time_point from, Clock::time_point to)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", std::chrono::duration<double, std::milli>(to - from).count());
    return std::string(name) + ";dur=" + buf;
}

std::int64_t path_integer(const std::string& text, std::string_view what, std::int64_t lo, std::int64_t hi)
{
    std::int64_t n = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), n);
    if (r.ec != std::errc() || r.ptr != text.data() + text.size() || n < lo || n > hi) {
        throw RequestError(400, std::string(what) + " = " + text + " is out of range: accepted " + std::to_string(lo) +
                                    " to " + std::to_string(hi));
    }
    return n;
}

class App {
public:
    App(const ServeSettings& s)
        : settings_(s),
          time_limit_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s.time_limit))),
          layers_(s.layers),
          pool_(s.threads ? s.threads : usable_cores(), max_pending_tasks)
    {
        routes();
    }

    HttpServer& http() { return http_; }

private:
    // Runs `blocks` calls of run(b) on the pool and waits for them, watching the client:
    // if it goes away the remaining blocks are dropped (ClientGone); past the time limit
    // the request is refused (503).
    void compute(const httplib::Request& req, std::size_t blocks, std::function<void(std::size_t)> run)
    {
        const auto task = std::make_shared<Task>(blocks, std::move(run), Clock::now() + time_limit_);
        if (!pool_.submit(task)) {
            throw RequestError(503, "the server is busy: " + std::to_string(max_pending_tasks) +
                                        " requests are waiting to be counted; accepted when fewer are");
        }
        ClientWatch watch(req);
        for (;;) {
            // Every block has finished or been dropped when wait_for says anything but
            // running: nothing refers to this frame any more.
            switch (task->wait_for(watch_interval)) {
                case Task::Status::running:
                    if (watch.gone()) task->cancel();
                    continue;
                case Task::Status::done: return;
                case Task::Status::cancelled: throw ClientGone{};
                case Task::Status::timed_out:
                    throw RequestError(503, "the request took longer than the server's time limit of " +
                                                format_double(settings_.time_limit) +
                                                " s (superball serve --time-limit): accepted fewer points or a "
                                                "smaller max_bounces; /api/job turns a region into a job for "
                                                "superball explore");
                case Task::Status::failed: std::rethrow_exception(task->error());
            }
        }
    }

    RegionCounts count_view(const httplib::Request& req, const View& v)
    {
        RegionWork work(v);
        compute(req, work.blocks(), [&](std::size_t b) { work.count_block(b); });
        return work.take();
    }

    // Answers with answer(q) for the query of `req`, whose parameters must be among
    // `accepted`; errors as {"error": ...} with their status.
    void handle(const httplib::Request& req, httplib::Response& res, std::vector<std::string> accepted,
                const std::function<void(Query&)>& answer)
    {
        try {
            Query q(req.params, std::move(accepted));
            answer(q);
        } catch (const ClientGone&) {
            res.status = 499;  // nobody reads it (nginx's code for a request the client closed)
            res.set_content("", "text/plain");
        } catch (const RequestError& e) {
            answer_error(res, e.status, e.what());
        } catch (const InputError& e) {
            answer_error(res, 400, e.what());
        } catch (const std::exception& e) {
            answer_error(res, 500, std::string("internal error: ") + e.what());
        }
    }

    void routes()
    {
        http_.Get("/", [](const httplib::Request&, httplib::Response& res) { asset(res, "/index.html"); });
        for (const WebAsset& a : web_assets()) {
            http_.Get(std::string(a.path), [&a](const httplib::Request&, httplib::Response& res) {
                res.set_content(a.body.data(), a.body.size(), std::string(a.content_type));
            });
        }
        http_.Get(R"(/leaflet/(leaflet\.js|leaflet\.css|images/[a-z0-9-]+\.png))",
                  [](const httplib::Request& req, httplib::Response& res) { leaflet(req.matches[1], res); });
        http_.Get("/api/info", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, {}, [&](Query&) {
                answer_json(res, 200, info());
            });
        });
        http_.Get("/api/count", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, keys({start_keys(), model_keys()}), [&](Query& q) { api_count(req, q, res); });
        });
        http_.Get("/api/trajectory", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, keys({start_keys(), model_keys(), {"samples"}}),
                   [&](Query& q) { api_trajectory(req, q, res); });
        });
        http_.Get("/api/region", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, view_keys(true), [&](Query& q) { api_region(req, q, res); });
        });
        http_.Get("/api/job", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, keys({view_keys(true), {"output"}}), [&](Query& q) { api_job(req, q, res); });
        });
        http_.Get("/api/legend", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, colouring_keys(), [&](Query& q) {
                const Colouring c = parse_colouring(q);
                answer_json(res, 200, legend_json(c));
            });
        });
        http_.Get(R"(/tile/(\d+)/(-?\d+)/(-?\d+)\.png)", [this](const httplib::Request& req, httplib::Response& res) {
            handle(req, res, keys({view_keys(false), colouring_keys(), {"layer"}}), [&](Query& q) { tile(req, q, res); });
        });
        // Unknown paths, other methods: what is accepted, as JSON like every other error.
        http_.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
            if (!res.body.empty()) return;
            if (res.status == 404 && req.method != "GET" && req.method != "HEAD") {
                answer_error(res, 405, "method " + req.method + " is not accepted: accepted GET");
            } else if (res.status == 404) {
                answer_error(res, 404, "no such path " + quote(req.path) +
                                           ": accepted / (the page), /api/count, /api/region, /api/trajectory, "
                                           "/api/job, /api/legend, /api/info, /tile/Z/X/Y.png");
            } else if (res.status == 414) {
                answer_error(res, 414, "the request's URL is too long: accepted at most " +
                                           std::to_string(CPPHTTPLIB_REQUEST_URI_MAX_LENGTH) + " characters");
            } else {
                answer_error(res, res.status, "the request was refused (HTTP " + std::to_string(res.status) +
                                                  "): accepted GET requests of HTTP/1.1");
            }
        });
    }

    static void asset(httplib::Response& res, std::string_view path)
    {
        for (const WebAsset& a : web_assets()) {
            if (a.path == path) res.set_content(a.body.data(), a.body.size(), std::string(a.content_type));
        }
    }

    static void leaflet(const std::string& name, httplib::Response& res)
    {
        const fs::path path = leaflet_directory() / name;
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            answer_error(res, 404, "cannot read " + path.string() + ": install Debian's libjs-leaflet");
            return;
        }
        std::ostringstream text;
        text << in.rdbuf();
        const std::string ext = path.extension().string();
        res.set_content(text.str(), ext == ".js" ? "text/javascript" : ext == ".css" ? "text/css" : "image/png");
        res.set_header("Cache-Control", "max-age=86400");
    }

    std::string info() const
    {
        const PoolStats s = pool_.stats();
        const Limits& l = settings_.limits;
        const nlohmann::ordered_json out = {
            {"software_version", software_version},
            {"threads", pool_.threads()},
            {"time_limit", settings_.time_limit},
            {"limits",
             {{"region_points", l.region_points},
              {"max_bounces", l.max_bounces},
              {"trajectory_bounces", l.trajectory_bounces},
              {"trajectory_points", l.trajectory_points},
              {"tile_size", tile_size}}},
            {"colour_maps", colour_map_names()},
            {"stats",
             {{"tasks", s.tasks},
              {"blocks_run", s.blocks_run},
              {"blocks_skipped", s.blocks_skipped},
              {"cancelled", s.cancelled},
              {"timed_out", s.timed_out},
              {"refused", s.refused},
              {"pending", s.pending}}},
            {"layers", layers_.json()}};
        return out.dump(1) + "\n";
    }

    void api_count(const httplib::Request& req, Query& q, httplib::Response& res)
    {
        ModelInput input;
        const Model model = parse_model(q, input);  // first, as the command line checks them
        const Start start = parse_start(q);
        const std::uint32_t max_bounces = parse_max_bounces(q, settings_.limits.max_bounces);
        BounceCount r;
        compute(req, 1, [&](std::size_t) { r = count(start.canonical, model, max_bounces); });
        answer_json(res, 200, count_json(r, start.canonical));
    }

    void api_trajectory(const httplib::Request& req, Query& q, httplib::Response& res)
    {
        ModelInput input;
        const Model model = parse_model(q, input);  // first, as the command line checks them
        const Start start = parse_start(q);
        const Limits& l = settings_.limits;
        const std::uint32_t max_bounces = parse_max_bounces(q, l.max_bounces);
        const int samples = static_cast<int>(q.integer("samples", 0, 100000, "0 or 2..100000").value_or(0));
        if (samples == 1) throw RequestError(400, "samples = 1 is out of range: accepted 0 or 2..100000");
        std::string body;
        compute(req, 1, [&](std::size_t) {
            // Its size first: the events are about twice the wall impacts.
            const BounceCount r = count(start.canonical, model, max_bounces);
            if (r.wall_bounces > l.trajectory_bounces) {
                throw RequestError(413, "the trajectory has " + std::to_string(r.wall_bounces) +
                                            " wall impacts: accepted at most " + std::to_string(l.trajectory_bounces) +
                                            " in one answer (a smaller max_bounces, or superball trajectory)");
            }
            const std::uint64_t points = (2 * std::uint64_t{r.wall_bounces} + 2) * static_cast<std::uint64_t>(samples);
            if (points > l.trajectory_points) {
                throw RequestError(413, "samples = " + std::to_string(samples) + " gives about " + std::to_string(points) +
                                            " path points: accepted at most " + std::to_string(l.trajectory_points) +
                                            " in one answer (fewer samples)");
            }
            body = trajectory_json(trajectory(start.state, model, start.frame.g, max_bounces, samples), start, model);
        });
        answer_json(res, 200, body);
    }

    void api_region(const httplib::Request& req, Query& q, httplib::Response& res)
    {
        const View v = parse_view(q, settings_.limits, true);
        const std::uint64_t limit = settings_.limits.region_points;
        if (v.x.n > limit || v.y.n > limit || v.x.n * v.y.n > limit) {
            throw RequestError(413, "nx x ny = " + std::to_string(v.x.n) + " x " + std::to_string(v.y.n) +
                                        " points: accepted at most " + std::to_string(limit) +
                                        " in one request (/api/job turns the region into a job for superball explore)");
        }
        const Clock::time_point start = Clock::now();
        const RegionCounts counts = count_view(req, v);
        const Clock::time_point counted = Clock::now();
        answer_json(res, 200, region_json(v, counts));
        res.set_header("Server-Timing", timing("count", start, counted) + ", " + timing("json", counted, Clock::now()));
    }

    void api_job(const httplib::Request& req, Query& q, httplib::Response& res)
    {
        Limits l = settings_.limits;
        l.max_bounces = std::numeric_limits<std::uint32_t>::max();  // the job runs elsewhere
        const View v = parse_view(q, l, true);
        const std::string output = q.text("output").value_or("results/view.h5");
        if (output.empty()) throw RequestError(400, "output = \"\" is empty: accepted a file path");
        // Where the job comes from: this server (its command line) and the request.
        const Provenance exported{process_command_line() + " (GET " + req.target + ")", utc_now(), 1, 1,
                                  static_cast<std::int64_t>(pool_.threads()), ""};
        const std::string text = job_toml(v, output, provenance_comment(exported, "# "));
        try {
            parse_job(text, "the exported job");  // what explore will say about it
        } catch (const InputError& e) {
            throw RequestError(400, e.what());
        }
        res.set_content(text, "application/toml; charset=utf-8");
    }

    void tile(const httplib::Request& req, Query& q, httplib::Response& res)
    {
        const int z = static_cast<int>(path_integer(req.matches[1], "z", 0, 1100));
        constexpr std::int64_t far = std::int64_t{1} << 53;
        const std::int64_t tx = path_integer(req.matches[2], "x", -far, far);
        const std::int64_t ty = path_integer(req.matches[3], "y", -far, far);
        const View window = parse_view(q, settings_.limits, false);
        const Colouring colouring = parse_colouring(q);
        std::optional<std::size_t> layer;
        if (q.has("layer")) {
            if (layers_.size() == 0) {
                throw RequestError(400, "layer is given, but superball serve was started with no result files: accepted "
                                        "no layer parameter");
            }
            layer = static_cast<std::size_t>(*q.integer("layer", 0, static_cast<std::int64_t>(layers_.size()) - 1,
                                                         "0 to " + std::to_string(layers_.size() - 1)));
        }
        const Clock::time_point start = Clock::now();
        const View v = tile_view(window, z, tx, ty, tile_size);
        const std::uint64_t points = tile_size * tile_size;
        RegionCounts counts{tile_size, tile_size, std::vector<std::uint32_t>(points), std::vector<std::uint8_t>(points)};
        std::vector<std::uint8_t> from_file(points), not_computed(points);
        const bool filled = layer && layers_.fill(*layer, v, counts, from_file, not_computed);
        if (!filled || std::find(from_file.begin(), from_file.end(), 0) != from_file.end()) {
            RegionCounts computed = count_view(req, v);
            for (std::uint64_t k = 0; k < points; ++k) {
                if (from_file[k]) continue;
                counts.wall_bounces[k] = computed.wall_bounces[k];
                counts.outcomes[k] = computed.outcomes[k];
            }
        }
        const Clock::time_point counted = Clock::now();
        res.set_content(tile_png(counts, colouring, not_computed), "image/png");
        res.set_header("Cache-Control", "max-age=3600");
        res.set_header("Server-Timing", timing("count", start, counted) + ", " + timing("png", counted, Clock::now()));
    }

    const ServeSettings settings_;
    const Clock::duration time_limit_;
    const Layers layers_;
    Pool pool_;
    HttpServer http_;
};

std::string url_of(const std::string& host, int port)
{
    const bool v6 = host.find(':') != std::string::npos;
    return "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
}

}  // namespace

void serve(const ServeSettings& settings, const std::function<void(const std::string& url)>& ready)
{
    if (!(settings.time_limit > 0 && settings.time_limit <= 86400)) {
        throw InputError("--time-limit = " + format_double(settings.time_limit) + " is out of range: accepted 0 < seconds <= 86400");
    }
    if (settings.port < 0 || settings.port > 65535) {
        throw InputError("--port = " + std::to_string(settings.port) + " is out of range: accepted 0 (any free port) to 65535");
    }
    // Signals to this thread and every thread it starts are blocked: SIGINT and SIGTERM
    // are taken by sigtimedwait below, SIGPIPE (a write to a client that left) is dropped.
    sigset_t signals;
    sigemptyset(&signals);
    for (const int s : {SIGINT, SIGTERM, SIGPIPE}) sigaddset(&signals, s);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    App app(settings);
    HttpServer& http = app.http();
    // cpp-httplib takes ownership of the queue it is given (a raw pointer is its interface).
    http.new_task_queue = [] { return new httplib::ThreadPool(connection_threads); };
    http.set_keep_alive_max_count(1000);
    errno = 0;
    int port = settings.port;
    const bool bound = port == 0 ? (port = http.bind_to_any_port(settings.host)) > 0 : http.bind_to_port(settings.host, port);
    if (!bound || !http.set_backlog(listen_backlog)) {
        const std::string why = errno ? std::string(": ") + std::strerror(errno) : "";
        throw std::runtime_error("cannot listen on " + settings.host + " port " + std::to_string(settings.port) + why);
    }
    ready(url_of(settings.host, port));

    std::atomic<bool> stopped{false};
    std::jthread stopper([&] {
        sigset_t wait_for;
        sigemptyset(&wait_for);
        sigaddset(&wait_for, SIGINT);
        sigaddset(&wait_for, SIGTERM);
        const timespec tick{0, 200'000'000};
        while (!stopped) {
            if (sigtimedwait(&wait_for, nullptr, &tick) > 0) break;
        }
        http.stop();
    });
    http.listen_after_bind();
    stopped = true;
}

}  // namespace superball::serve
