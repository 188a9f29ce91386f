// SPDX-License-Identifier: MIT
// The viewer's web server: one thread runs Boost.Asio; every browser is a session that
// holds at most one frame waiting, so a slow or vanished browser costs nothing.
#include "viewer/server.hpp"

#include "core/error.hpp"
#include "viewer/web_files.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <spdlog/spdlog.h>

#include <atomic>
#include <deque>
#include <mutex>
#include <random>
#include <set>
#include <thread>

namespace binocle::viewer {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

// Texts a browser has not read yet beyond this: it is gone or stuck; it is dropped.
constexpr size_t kMaxQueuedTexts = 256;
// A page says when it has shown a frame (kShownMessage); one that does not (an old page,
// a hidden tab) gets the next frame after this long.
constexpr auto kShownTimeout = std::chrono::seconds(2);

std::string percentDecode(const std::string &s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
            out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += s[i] == '+' ? ' ' : s[i];
        }
    }
    return out;
}

std::string queryValue(const std::string &query, const std::string &key) {
    size_t pos = 0;
    while (pos <= query.size()) {
        size_t end = query.find('&', pos);
        if (end == std::string::npos) end = query.size();
        const std::string part = query.substr(pos, end - pos);
        const size_t eq = part.find('=');
        if (part.substr(0, eq) == key) return eq == std::string::npos ? "" : percentDecode(part.substr(eq + 1));
        pos = end + 1;
    }
    return "";
}

// Same length and bytes, in a time that does not depend on where they differ.
bool sameSecret(const std::string &a, const std::string &b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

std::string mimeOf(const std::string &path) {
    auto ends = [&](const char *ext) {
        const std::string e(ext);
        return path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
    };
    if (ends(".html")) return "text/html; charset=utf-8";
    if (ends(".js")) return "text/javascript; charset=utf-8";
    if (ends(".css")) return "text/css; charset=utf-8";
    if (ends(".png")) return "image/png";
    if (ends(".svg")) return "image/svg+xml";
    return "application/octet-stream";
}

class WsSession;

} // namespace

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
    net::io_context io{1};
    tcp::acceptor acceptor{io};
    std::string address, token;
    ServerHandlers handlers;
    std::thread thread;
    mutable std::mutex mutex;
    std::set<std::shared_ptr<WsSession>> sessions; // open WebSockets

    void accept();
    void add(const std::shared_ptr<WsSession> &s) {
        std::lock_guard<std::mutex> lock(mutex);
        sessions.insert(s);
    }
    void remove(const std::shared_ptr<WsSession> &s) {
        std::lock_guard<std::mutex> lock(mutex);
        sessions.erase(s);
    }
    std::vector<std::shared_ptr<WsSession>> snapshot() const {
        std::lock_guard<std::mutex> lock(mutex);
        return {sessions.begin(), sessions.end()};
    }
};

namespace {

class WsSession : public std::enable_shared_from_this<WsSession> {
public:
    WsSession(tcp::socket &&socket, std::shared_ptr<Server::Impl> server) : ws_(std::move(socket)), server_(std::move(server)) {}

    void run(http::request<http::string_body> request) {
        ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
        ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
            if (ec) return;
            self->server_->add(self);
            if (self->server_->handlers.hello) self->pushText(std::make_shared<const std::string>(self->server_->handlers.hello()));
            if (self->server_->handlers.lastFrame)
                if (auto f = self->server_->handlers.lastFrame()) self->pushFrame(f);
            self->read();
        });
    }

    // From any thread.
    void queueText(std::shared_ptr<const std::string> text) {
        net::post(ws_.get_executor(), [self = shared_from_this(), text] { self->pushText(text); });
    }
    void queueFrame(std::shared_ptr<const std::string> frame) {
        ready_ = false;
        net::post(ws_.get_executor(), [self = shared_from_this(), frame] { self->pushFrame(frame); });
    }
    // Nothing to write, and the page has shown the last frame (or took too long to say).
    bool ready() const {
        return ready_ && (!showing_ || std::chrono::steady_clock::now().time_since_epoch().count() > shownDeadline_.load());
    }

private:
    void pushText(std::shared_ptr<const std::string> text) {
        if (closed_) return;
        if (texts_.size() >= kMaxQueuedTexts) return drop();
        texts_.push_back(std::move(text));
        pump();
    }
    void pushFrame(std::shared_ptr<const std::string> frame) {
        if (closed_) return;
        frame_ = std::move(frame); // an older frame still waiting is skipped
        pump();
    }
    void pump() {
        if (writing_ || closed_) return;
        bool binary = false;
        if (!texts_.empty()) {
            current_ = texts_.front();
            texts_.pop_front();
        } else if (frame_) {
            current_ = std::move(frame_);
            frame_.reset();
            binary = true;
            shownDeadline_ = (std::chrono::steady_clock::now() + kShownTimeout).time_since_epoch().count();
            showing_ = true;
        } else {
            ready_ = true;
            return;
        }
        writing_ = true;
        ws_.binary(binary);
        ws_.async_write(net::buffer(*current_), [self = shared_from_this()](beast::error_code ec, size_t) {
            self->writing_ = false;
            self->current_.reset();
            if (ec) return self->drop();
            self->pump();
        });
    }
    void read() {
        ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code ec, size_t) {
            if (ec) return self->drop();
            if (self->ws_.got_text()) {
                const std::string text = beast::buffers_to_string(self->buffer_.data());
                if (text == kShownMessage) {
                    self->showing_ = false; // flow control: this browser is ready for the next frame
                } else if (self->server_->handlers.command) {
                    const std::string reply = self->server_->handlers.command(text);
                    if (!reply.empty()) self->pushText(std::make_shared<const std::string>(reply));
                }
            }
            self->buffer_.consume(self->buffer_.size());
            self->read();
        });
    }
    void drop() {
        if (closed_) return;
        closed_ = true;
        ready_ = false;
        texts_.clear();
        frame_.reset();
        beast::error_code ignored;
        beast::get_lowest_layer(ws_).socket().close(ignored);
        server_->remove(shared_from_this());
    }

    websocket::stream<beast::tcp_stream> ws_;
    std::shared_ptr<Server::Impl> server_;
    beast::flat_buffer buffer_;
    std::deque<std::shared_ptr<const std::string>> texts_;
    std::shared_ptr<const std::string> frame_, current_;
    bool writing_ = false, closed_ = false;
    std::atomic<bool> ready_{false};
    // A frame was written and the page has not said it has shown it (before the deadline,
    // steady_clock ticks).
    std::atomic<bool> showing_{false};
    std::atomic<int64_t> shownDeadline_{0};
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
public:
    HttpSession(tcp::socket &&socket, std::shared_ptr<Server::Impl> server) : stream_(std::move(socket)), server_(std::move(server)) {}
    void run() { read(); }

private:
    void read() {
        request_ = {};
        stream_.expires_after(std::chrono::seconds(30));
        http::async_read(stream_, buffer_, request_, [self = shared_from_this()](beast::error_code ec, size_t) {
            if (ec) {
                beast::error_code ignored;
                self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                return;
            }
            self->handle();
        });
    }

    void reply(int status, const std::string &type, std::string body, const std::string &filename = "") {
        auto res = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(status), request_.version());
        res->set(http::field::server, "binocle-view");
        res->set(http::field::content_type, type);
        res->set(http::field::cache_control, "no-store");
        // The page loads nothing from elsewhere; say so to the browser too.
        res->set("Content-Security-Policy",
                 "default-src 'self'; img-src 'self' blob: data:; connect-src 'self' ws: blob:; style-src 'self' 'unsafe-inline'");
        res->set("X-Content-Type-Options", "nosniff");
        if (!filename.empty()) res->set(http::field::content_disposition, "attachment; filename=\"" + filename + "\"");
        res->keep_alive(request_.keep_alive());
        res->body() = request_.method() == http::verb::head ? std::string() : std::move(body);
        res->prepare_payload();
        http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, size_t) {
            if (ec) return;
            if (!res->keep_alive()) {
                beast::error_code ignored;
                self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                return;
            }
            self->read();
        });
    }

    void handle() {
        const std::string host(request_[http::field::host]);
        if (!Server::isLocalHost(host, server_->address)) {
            spdlog::warn("view: refused a request for Host '{}' (only this machine's loopback names are served)", host);
            return reply(403, "text/plain", "binocle view: Host '" + host + "' is not served: open the URL printed at start\n");
        }
        const std::string target(request_.target());
        const size_t q = target.find('?');
        const std::string path = target.substr(0, q);
        const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
        const bool tokenOk = sameSecret(queryValue(query, "token"), server_->token);

        if (websocket::is_upgrade(request_)) {
            if (path != "/ws") return reply(404, "text/plain", "no WebSocket at " + path + "\n");
            if (!tokenOk) return reply(403, "text/plain", "binocle view: missing or wrong token\n");
            const std::string origin(request_[http::field::origin]);
            if (!origin.empty()) {
                const size_t scheme = origin.find("://");
                const std::string originHost = scheme == std::string::npos ? origin : origin.substr(scheme + 3);
                if (!Server::isLocalHost(originHost, server_->address))
                    return reply(403, "text/plain", "binocle view: Origin '" + origin + "' is not served\n");
            }
            stream_.expires_never();
            std::make_shared<WsSession>(stream_.release_socket(), server_)->run(std::move(request_));
            return;
        }
        if (path.rfind("/api/", 0) == 0) {
            if (!tokenOk) return reply(403, "text/plain", "binocle view: missing or wrong token\n");
            const std::string name = path.substr(5);
            if (request_.method() == http::verb::post && name == "command") {
                if (!server_->handlers.command) return reply(404, "text/plain", "no commands\n");
                return reply(200, "application/json", server_->handlers.command(request_.body()));
            }
            if (request_.method() != http::verb::get && request_.method() != http::verb::head)
                return reply(405, "text/plain", "method not allowed\n");
            HttpReply r = server_->handlers.api ? server_->handlers.api(name) : HttpReply{404, "text/plain", "", ""};
            if (r.status == 404 && r.body.empty()) r.body = "no API named " + name + "\n";
            return reply(r.status, r.content_type, std::move(r.body), r.filename);
        }
        if (request_.method() != http::verb::get && request_.method() != http::verb::head)
            return reply(405, "text/plain", "method not allowed\n");
        const std::string file = path == "/" ? "index.html" : path.substr(1);
        const EmbeddedFile *f = webFile(file);
        if (!f) return reply(404, "text/plain", "not found: " + path + "\n");
        return reply(200, mimeOf(file), std::string(reinterpret_cast<const char *>(f->data), f->size));
    }

    beast::tcp_stream stream_;
    beast::flat_buffer buffer_;
    http::request<http::string_body> request_;
    std::shared_ptr<Server::Impl> server_;
};

} // namespace

void Server::Impl::accept() {
    acceptor.async_accept(net::make_strand(io), [self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
        if (ec == net::error::operation_aborted) return;
        if (!ec) std::make_shared<HttpSession>(std::move(socket), self)->run();
        self->accept();
    });
}

Server::Server(const std::string &address, uint16_t port, std::string token, ServerHandlers handlers)
    : impl_(std::make_shared<Impl>()) {
    impl_->address = address;
    impl_->token = std::move(token);
    impl_->handlers = std::move(handlers);
    beast::error_code ec;
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
    impl_->thread = std::thread([impl = impl_] { impl->io.run(); });
}

Server::~Server() {
    net::post(impl_->io, [impl = impl_] {
        beast::error_code ignored;
        impl->acceptor.close(ignored);
    });
    impl_->io.stop();
    if (impl_->thread.joinable()) impl_->thread.join();
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->sessions.clear();
}

uint16_t Server::port() const { return impl_->acceptor.local_endpoint().port(); }
const std::string &Server::token() const { return impl_->token; }

std::string Server::url() const {
    std::string host = impl_->address;
    if (host.find(':') != std::string::npos) host = "[" + host + "]";
    return "http://" + host + ":" + std::to_string(port()) + "/?token=" + impl_->token;
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

bool Server::isLocalHost(const std::string &host, const std::string &boundAddress) {
    std::string name = host;
    if (!name.empty() && name.front() == '[') { // [::1]:port
        const size_t close = name.find(']');
        if (close == std::string::npos) return false;
        const std::string rest = name.substr(close + 1);
        if (!rest.empty() && (rest[0] != ':' || rest.find_first_not_of("0123456789", 1) != std::string::npos)) return false;
        name = name.substr(1, close - 1);
    } else if (const size_t colon = name.find(':'); colon != std::string::npos && name.find(':', colon + 1) == std::string::npos) {
        if (name.find_first_not_of("0123456789", colon + 1) != std::string::npos) return false;
        name = name.substr(0, colon);
    }
    for (char &c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (name == "localhost" || name == "::1" || name == boundAddress) return true;
    // 127.0.0.0/8 is loopback.
    beast::error_code ec;
    const auto ip = net::ip::make_address_v4(name, ec);
    return !ec && ip.is_loopback();
}

std::string makeToken() {
    std::random_device rd;
    static const char *hex = "0123456789abcdef";
    std::string t;
    for (int i = 0; i < 32; ++i) t += hex[rd() & 15];
    return t;
}

} // namespace binocle::viewer
