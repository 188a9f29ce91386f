// SPDX-License-Identifier: MIT
// One connection each: an HTTP session (the page, the API, commands by POST) that may
// become a WebSocket session (state, frames, commands). Every check of a request is here,
// in the order a request meets them: size, Host, token, origin, anti-forgery header.
#include "viewer/command.hpp"
#include "viewer/server_impl.hpp"
#include "viewer/web_files.hpp"

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <spdlog/spdlog.h>

#include <optional>

namespace binocle::viewer::detail {

namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

// A page says when it has shown a frame (kShownMessage); one that does not (an old page,
// a hidden tab) gets the next frame after this long.
constexpr auto kShownTimeout = std::chrono::seconds(2);
// An HTTP connection that sends no complete request for this long is closed.
constexpr auto kHttpIdle = std::chrono::seconds(30);

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

void logLimited(LogLimiter &limiter, const std::string &line) {
    size_t suppressed = 0;
    if (!limiter.allow(suppressed)) return;
    if (suppressed > 0) spdlog::warn("{} ({} similar lines left out)", line, suppressed);
    else spdlog::warn("{}", line);
}

class WebSocketSession final : public WsSession {
public:
    WebSocketSession(tcp::socket &&socket, std::shared_ptr<Server::Impl> server, ConnectionSlot slot)
        : ws_(std::move(socket)), server_(std::move(server)), slot_(std::move(slot)) {}

    void run(http::request<http::string_body> request) {
        websocket::stream_base::timeout t = websocket::stream_base::timeout::suggested(beast::role_type::server);
        // A browser answers pings even in a background tab; a client that reads nothing
        // does not, and is closed instead of holding its queue for ever.
        t.idle_timeout = std::chrono::seconds(60);
        t.keep_alive_pings = true;
        ws_.set_option(t);
        ws_.read_message_max(kMaxCommandBytes);
        ws_.async_accept(request, [self = shared_this()](beast::error_code ec) {
            if (ec) return;
            self->server_->add(self);
            if (self->server_->handlers.hello) self->pushText(std::make_shared<const std::string>(self->server_->handlers.hello()));
            if (self->server_->handlers.lastFrame)
                if (auto f = self->server_->handlers.lastFrame()) self->pushFrame(f);
            self->read();
        });
    }

    void queueText(std::shared_ptr<const std::string> text) override {
        net::post(ws_.get_executor(), [self = shared_this(), text] { self->pushText(text); });
    }
    void queueState(std::shared_ptr<const std::string> text) override {
        net::post(ws_.get_executor(), [self = shared_this(), text] {
            self->state_ = text; // an older state still waiting is superseded
            self->pump();
        });
    }
    void queueFrame(std::shared_ptr<const std::string> frame) override {
        ready_ = false;
        net::post(ws_.get_executor(), [self = shared_this(), frame] { self->pushFrame(frame); });
    }
    void close() override {
        net::post(ws_.get_executor(), [self = shared_this()] { self->drop(); });
    }
    bool ready() const override {
        return ready_ && (!showing_ || std::chrono::steady_clock::now().time_since_epoch().count() > shownDeadline_.load());
    }

private:
    std::shared_ptr<WebSocketSession> shared_this() { return std::static_pointer_cast<WebSocketSession>(shared_from_this()); }

    void pushText(std::shared_ptr<const std::string> text) {
        if (closed_) return;
        if (texts_.size() >= kMaxQueuedTexts || queuedBytes_ + text->size() > kMaxQueuedTextBytes) return drop();
        queuedBytes_ += text->size();
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
            queuedBytes_ -= current_->size();
        } else if (state_) {
            current_ = std::move(state_);
            state_.reset();
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
        ws_.async_write(net::buffer(*current_), [self = shared_this()](beast::error_code ec, size_t) {
            self->writing_ = false;
            self->current_.reset();
            if (ec) return self->drop();
            self->pump();
        });
    }
    void read() {
        ws_.async_read(buffer_, [self = shared_this()](beast::error_code ec, size_t) {
            if (ec) {
                if (ec == websocket::error::message_too_big)
                    logLimited(self->server_->refusedLog, "view: closed a WebSocket that sent a message over " +
                                                              std::to_string(kMaxCommandBytes) + " bytes");
                return self->drop();
            }
            if (self->ws_.got_text()) {
                std::string text = beast::buffers_to_string(self->buffer_.data());
                if (text == kShownMessage) {
                    self->showing_ = false; // flow control: this browser is ready for the next frame
                } else {
                    std::weak_ptr<WsSession> weak = self;
                    self->server_->submit(std::move(text), [weak](std::string reply) {
                        if (reply.empty()) return;
                        if (auto s = weak.lock()) s->queueText(std::make_shared<const std::string>(std::move(reply)));
                    });
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
        queuedBytes_ = 0;
        state_.reset();
        frame_.reset();
        beast::error_code ignored;
        beast::get_lowest_layer(ws_).socket().close(ignored);
        server_->remove(shared_this());
    }

    websocket::stream<beast::tcp_stream> ws_;
    std::shared_ptr<Server::Impl> server_;
    ConnectionSlot slot_;
    beast::flat_buffer buffer_;
    std::deque<std::shared_ptr<const std::string>> texts_;
    size_t queuedBytes_ = 0;
    std::shared_ptr<const std::string> state_, frame_, current_;
    bool writing_ = false, closed_ = false;
    std::atomic<bool> ready_{false};
    // A frame was written and the page has not said it has shown it (before the deadline,
    // steady_clock ticks).
    std::atomic<bool> showing_{false};
    std::atomic<int64_t> shownDeadline_{0};
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
public:
    HttpSession(tcp::socket &&socket, std::shared_ptr<Server::Impl> server, ConnectionSlot slot)
        : stream_(std::move(socket)), server_(std::move(server)), slot_(std::move(slot)) {
        beast::error_code ec;
        const auto local = stream_.socket().local_endpoint(ec);
        if (!ec) localAddress_ = local.address().to_string();
    }
    void run() { read(); }

private:
    void read() {
        parser_.emplace();
        parser_->header_limit(kMaxHeaderBytes);
        parser_->body_limit(kMaxCommandBytes);
        stream_.expires_after(kHttpIdle);
        http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, size_t) {
            if (ec == http::error::body_limit || ec == http::error::header_limit) {
                logLimited(self->server_->refusedLog, "view: refused a request over its size limit (" + ec.message() + ")");
                self->request_ = {};
                self->keepAlive_ = false;
                return self->reply(413, "text/plain", "binocle view: request too large: a command is at most " +
                                                          std::to_string(kMaxCommandBytes) + " bytes, headers at most " +
                                                          std::to_string(kMaxHeaderBytes) + "\n");
            }
            if (ec) {
                beast::error_code ignored;
                self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                return;
            }
            self->request_ = self->parser_->release();
            self->keepAlive_ = self->request_.keep_alive();
            self->handle();
        });
    }

    void reply(int status, const std::string &type, std::string body, const std::string &filename = "") {
        auto res = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(status), request_.version());
        res->set(http::field::server, "binocle-view");
        // A handler's content type reaches the header only if it cannot start another.
        res->set(http::field::content_type, headerSafe(type) ? type : "application/octet-stream");
        res->set(http::field::cache_control, "no-store");
        // The page loads nothing from elsewhere, is framed by no one and sends no Referer
        // (its URL carries the token).
        res->set("Content-Security-Policy", "default-src 'self'; img-src 'self' blob: data:; connect-src 'self' ws: blob:; "
                                            "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'");
        res->set("X-Content-Type-Options", "nosniff");
        res->set("X-Frame-Options", "DENY");
        res->set("Referrer-Policy", "no-referrer");
        if (!filename.empty())
            res->set(http::field::content_disposition, "attachment; filename=\"" + safeFileName(filename, "download") + "\"");
        res->keep_alive(keepAlive_);
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
    void refuse(int status, const std::string &why) { reply(status, "text/plain", "binocle view: " + why + "\n"); }

    void handle() {
        const std::string host(request_[http::field::host]);
        if (!hostAllowed(host, localAddress_, server_->options.allowed_hosts)) {
            logLimited(server_->refusedLog, "view: refused a request for Host '" + logExcerpt(host) + "' arriving on " + localAddress_);
            return refuse(403, "this Host is not served: open the URL printed at start (or see --allow-host)");
        }
        const std::string target(request_.target());
        const size_t q = target.find('?');
        const std::string path = target.substr(0, q);
        const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
        const bool tokenOk = sameSecret(queryValue(query, "token"), server_->options.token);
        const std::string origin(request_[http::field::origin]);
        // Browsers send Origin with every WebSocket and POST; its host and port must be
        // this page's. A client without Origin is not a browser acting for a page.
        const bool originOk = origin.empty() || sameOrigin(origin, host);

        if (websocket::is_upgrade(request_)) {
            if (path != "/ws") return refuse(404, "no WebSocket at this path");
            if (!tokenOk) return refuse(403, "missing or wrong token");
            if (!originOk) {
                logLimited(server_->refusedLog, "view: refused a WebSocket from Origin '" + logExcerpt(origin) + "'");
                return refuse(403, "this Origin is not served (the page's own scheme, host and port only)");
            }
            stream_.expires_never();
            auto ws = std::make_shared<WebSocketSession>(stream_.release_socket(), server_, std::move(slot_));
            ws->run(std::move(request_));
            return;
        }
        if (path.rfind("/api/", 0) == 0) {
            const std::string name = path.substr(5);
            if (request_.method() == http::verb::post && name == "command") return command(originOk);
            if (!tokenOk) return refuse(403, "missing or wrong token");
            if (request_.method() != http::verb::get && request_.method() != http::verb::head)
                return refuse(405, "method not allowed");
            HttpReply r = server_->handlers.api ? server_->handlers.api(name) : HttpReply{404, "text/plain", "", ""};
            if (r.status == 404 && r.body.empty()) r.body = "no API of this name\n";
            return reply(r.status, r.content_type, std::move(r.body), r.filename);
        }
        if (request_.method() != http::verb::get && request_.method() != http::verb::head) return refuse(405, "method not allowed");
        const std::string file = path == "/" ? "index.html" : path.substr(1);
        const EmbeddedFile *f = webFile(file);
        if (!f) return refuse(404, "not found");
        return reply(200, mimeOf(file), std::string(reinterpret_cast<const char *>(f->data), f->size));
    }

    // POST /api/command: a state-changing request. The token must come in kTokenHeader
    // (a cross-origin form cannot send a header; a cross-origin script would need a
    // preflight, which is refused), and a browser's Origin must be this page's.
    void command(bool originOk) {
        const std::string token(request_[kTokenHeader]);
        if (!sameSecret(token, server_->options.token))
            return refuse(403, std::string("a command needs the token in the ") + kTokenHeader + " header");
        const std::string site(request_["Sec-Fetch-Site"]);
        if (!originOk || (!site.empty() && site != "same-origin" && site != "none")) {
            logLimited(server_->refusedLog, "view: refused a cross-origin command from Origin '" +
                                                logExcerpt(std::string(request_[http::field::origin])) + "'");
            return refuse(403, "a command from another origin is refused");
        }
        if (!server_->handlers.command) return refuse(404, "no commands");
        // The reply comes from the command thread; this connection waits for it.
        auto self = shared_from_this();
        server_->submit(request_.body(), [self](std::string reply) {
            net::post(self->stream_.get_executor(), [self, reply = std::move(reply)]() mutable {
                self->reply(200, "application/json", std::move(reply));
            });
        });
    }

    beast::tcp_stream stream_;
    std::shared_ptr<Server::Impl> server_;
    ConnectionSlot slot_;
    std::string localAddress_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    http::request<http::string_body> request_;
    bool keepAlive_ = false;
};

} // namespace

void startHttpSession(tcp::socket &&socket, std::shared_ptr<Server::Impl> server, ConnectionSlot slot) {
    std::make_shared<HttpSession>(std::move(socket), std::move(server), std::move(slot))->run();
}

} // namespace binocle::viewer::detail
