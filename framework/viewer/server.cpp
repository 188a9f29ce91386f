// SPDX-License-Identifier: MIT
// The viewer's web server: one I/O thread runs Boost.Asio (accepting with a cap and a
// back-off, the sessions of sessions.cpp), one command thread runs the page's commands,
// so that slow work never stalls a connection.
#include "viewer/server.hpp"

#include "core/error.hpp"
#include "viewer/server_impl.hpp"

#include <spdlog/spdlog.h>

#include <dirent.h>
#include <random>
#include <sys/resource.h>

namespace binocle::viewer {

namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

const char *const kBusy = R"({"type":"error","message":"view: too many commands are waiting; try again in a moment"})";

// Connections a process may hold now: half of the file descriptors still free under its
// limit (frames and snapshots need the rest), at most 128.
size_t connectionsTheLimitAllows() {
    rlimit limit{};
    if (getrlimit(RLIMIT_NOFILE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return 128;
    size_t open = 0;
    if (DIR *d = opendir("/proc/self/fd")) {
        while (readdir(d)) ++open;
        closedir(d);
    }
    const size_t free = limit.rlim_cur > open ? limit.rlim_cur - open : 0;
    return std::clamp<size_t>(free / 2, 4, 128);
}

} // namespace

detail::ConnectionSlot Server::Impl::takeSlot() {
    ++connections;
    return detail::ConnectionSlot(nullptr, [self = shared_from_this()](void *) { --self->connections; });
}

void Server::Impl::accept() {
    acceptor.async_accept(net::make_strand(io), [self = shared_from_this()](boost::system::error_code ec, tcp::socket socket) {
        if (ec == net::error::operation_aborted || self->stopped) return;
        if (ec) return self->acceptLater(ec);
        self->acceptBackoff = std::chrono::milliseconds(0);
        if (self->connections >= self->maxConnections) {
            size_t suppressed = 0;
            if (self->connectionLog.allow(suppressed))
                spdlog::warn("view: {} connections are open (the most this view holds); closed a new one{}", self->maxConnections,
                             suppressed ? " (" + std::to_string(suppressed) + " more left out of the log)" : "");
            boost::system::error_code ignored;
            socket.close(ignored);
        } else {
            detail::startHttpSession(std::move(socket), self, self->takeSlot());
        }
        self->accept();
    });
}

// accept() failed (out of file descriptors, most often): the listening socket stays
// readable, so accepting again at once would spin; wait, longer each time, up to 1 s.
void Server::Impl::acceptLater(const boost::system::error_code &ec) {
    acceptBackoff = std::min(std::chrono::milliseconds(1000), std::max(std::chrono::milliseconds(10), acceptBackoff * 2));
    size_t suppressed = 0;
    if (connectionLog.allow(suppressed))
        spdlog::warn("view: cannot accept a connection: {}; trying again in {} ms{}", ec.message(), acceptBackoff.count(),
                     suppressed ? " (" + std::to_string(suppressed) + " more left out of the log)" : "");
    acceptRetry.expires_after(acceptBackoff);
    acceptRetry.async_wait([self = shared_from_this()](boost::system::error_code wait) {
        if (!wait && !self->stopped) self->accept();
    });
}

void Server::Impl::submit(std::string text, std::function<void(std::string)> respond) {
    {
        std::lock_guard<std::mutex> lock(jobsMutex);
        if (!workerQuit && jobs.size() < detail::kMaxPendingCommands) {
            jobs.push_back({std::move(text), std::move(respond)});
            jobsCv.notify_one();
            return;
        }
    }
    respond(kBusy);
}

void Server::Impl::workLoop() {
    std::unique_lock<std::mutex> lock(jobsMutex);
    for (;;) {
        jobsCv.wait(lock, [&] { return workerQuit || !jobs.empty(); });
        if (workerQuit) return;
        Job job = std::move(jobs.front());
        jobs.pop_front();
        lock.unlock();
        std::string reply;
        try {
            reply = handlers.command ? handlers.command(job.text) : std::string();
        } catch (const std::exception &e) {
            spdlog::error("view: a command failed: {}", logExcerpt(e.what()));
            reply = R"j({"type":"error","message":"view: the command failed (see the log)"})j";
        }
        job.respond(std::move(reply));
        lock.lock();
    }
}

Server::Server(ServerOptions options, ServerHandlers handlers) : impl_(std::make_shared<Impl>()) {
    impl_->options = std::move(options);
    impl_->handlers = std::move(handlers);
    impl_->maxConnections = impl_->options.max_connections > 0 ? impl_->options.max_connections : connectionsTheLimitAllows();
    const std::string &address = impl_->options.address;
    const uint16_t port = impl_->options.port;
    boost::system::error_code ec;
    const auto ip = net::ip::make_address(address, ec);
    if (ec) throw Error("view: --bind " + address + ": not an IP address (" + ec.message() + ")");
    const tcp::endpoint endpoint(ip, port);
    impl_->acceptor.open(endpoint.protocol(), ec);
    if (!ec) impl_->acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) impl_->acceptor.bind(endpoint, ec);
    if (!ec) impl_->acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec)
        throw Error("view: cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message() +
                    (ec == net::error::address_in_use ? " (choose another --port, or --port 0 for any free one)" : ""));
    impl_->accept();
    impl_->worker = std::thread([impl = impl_.get()] { impl->workLoop(); });
    impl_->thread = std::thread([impl = impl_] { impl->io.run(); });
}

Server::~Server() { stop(); }

void Server::stop() {
    if (impl_->stopped.exchange(true)) return;
    {
        std::lock_guard<std::mutex> lock(impl_->jobsMutex);
        impl_->workerQuit = true;
        for (auto &job : impl_->jobs) job.respond(kBusy);
        impl_->jobs.clear();
    }
    impl_->jobsCv.notify_all();
    if (impl_->worker.joinable()) impl_->worker.join();
    net::post(impl_->io, [impl = impl_] {
        boost::system::error_code ignored;
        impl->acceptor.close(ignored);
        impl->acceptRetry.cancel();
    });
    impl_->io.stop();
    if (impl_->thread.joinable()) impl_->thread.join();
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->sessions.clear();
}

uint16_t Server::port() const { return impl_->acceptor.local_endpoint().port(); }
const std::string &Server::token() const { return impl_->options.token; }
size_t Server::maxConnections() const { return impl_->maxConnections; }
size_t Server::connections() const { return impl_->connections; }

std::string Server::url() const {
    std::string host = impl_->options.address;
    // A browser cannot open 0.0.0.0 or ::; the loopback name reaches it from this machine.
    if (host == "0.0.0.0") host = "127.0.0.1";
    if (host == "::") host = "::1";
    if (host.find(':') != std::string::npos) host = "[" + host + "]";
    return "http://" + host + ":" + std::to_string(port()) + "/?token=" + impl_->options.token;
}

bool Server::wantsFrame() const {
    for (const auto &s : impl_->snapshot())
        if (s->ready()) return true;
    return false;
}

size_t Server::browsers() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->sessions.size();
}

void Server::broadcastFrame(std::shared_ptr<const std::string> binary) {
    for (const auto &s : impl_->snapshot()) s->queueFrame(binary);
}

void Server::broadcastText(const std::string &text) {
    auto shared = std::make_shared<const std::string>(text);
    for (const auto &s : impl_->snapshot()) s->queueText(shared);
}

void Server::broadcastState(const std::string &text) {
    auto shared = std::make_shared<const std::string>(text);
    for (const auto &s : impl_->snapshot()) s->queueState(shared);
}

std::string makeToken() {
    std::random_device rd;
    static const char *hex = "0123456789abcdef";
    std::string t;
    for (int i = 0; i < 32; ++i) t += hex[rd() & 15];
    return t;
}

} // namespace binocle::viewer
