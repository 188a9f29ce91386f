// SPDX-License-Identifier: MIT
// The viewer's web server (Boost.Beast): the embedded page over HTTP, frames and
// commands over WebSocket, behind a token, a Host rule, a same-origin rule with the port,
// an anti-forgery header on POST, size caps and a connection cap (docs/security.md).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace binocle::viewer {

// What a page sends once it has shown a frame: the server's flow control, so that a
// browser gets frames no faster than it can draw them.
inline constexpr const char *kShownMessage = R"({"op":"shown"})";
// A POST must carry the token in this header: a form or a simple request from another
// origin cannot set it, and a script there would need a CORS preflight this server
// never grants.
inline constexpr const char *kTokenHeader = "X-Binocle-Token";

struct HttpReply {
    int status = 200;
    std::string content_type = "application/json";
    std::string body;
    std::string filename; // set: sent as an attachment (a download), made safe by the server
};

struct ServerHandlers {
    // Text message a browser gets when its WebSocket opens (the current state). Runs on
    // the I/O thread: keep it short.
    std::function<std::string()> hello;
    // A command from a browser (WebSocket text or POST /api/command), JSON of at most
    // kMaxCommandBytes; the reply goes back to that browser only. Runs on the server's
    // command thread, one command at a time in the order they came: it may take a while
    // (a snapshot) without stalling any connection.
    std::function<std::string(const std::string &command)> command;
    // GET /api/<name> (token already checked); status 404 for unknown names. Runs on the
    // I/O thread: keep it short.
    std::function<HttpReply(const std::string &name)> api;
    // Binary message a browser gets after `hello`: the last frame, if any.
    std::function<std::shared_ptr<const std::string>()> lastFrame;
};

struct ServerOptions {
    std::string address = "127.0.0.1"; // an IP literal
    uint16_t port = 0;                  // 0: any free port
    std::string token;
    // Host names served besides the address a connection arrived on (and localhost on
    // loopback): --allow-host, for a DNS name of this machine.
    std::vector<std::string> allowed_hosts;
    // Most connections (HTTP and WebSocket) open at once; 0: from the file-descriptor
    // limit left at start, at most 128. More are closed as they come.
    size_t max_connections = 0;
};

class Server {
public:
    // Binds and serves on a thread of its own. Throws binocle::Error naming the address
    // when it cannot bind.
    Server(ServerOptions options, ServerHandlers handlers);
    ~Server(); // stop()

    // Finishes the command running, closes every connection and joins the threads; no
    // handler is called afterwards. Idempotent.
    void stop();

    uint16_t port() const;
    const std::string &token() const;
    std::string url() const; // http://ADDRESS:PORT/?token=...
    size_t maxConnections() const;
    size_t connections() const; // open now, HTTP and WebSocket

    // True when some browser has no frame waiting or being written and has shown the last
    // one (its page sends kShownMessage once it has): only then is a frame worth encoding.
    bool wantsFrame() const;
    size_t browsers() const;
    // Every browser gets the newest frame; one still sending an older frame gets this
    // one next, and the frames between are skipped (for that browser only).
    void broadcastFrame(std::shared_ptr<const std::string> binary);
    // Every browser gets this text (errors, notes), in order. A browser that lets more
    // than a few megabytes of them wait is dropped.
    void broadcastText(const std::string &text);
    // The newest state: a browser that has not taken the last one gets this one instead
    // (a state supersedes the one before it; nothing piles up).
    void broadcastState(const std::string &text);

    struct Impl;

private:
    std::shared_ptr<Impl> impl_;
};

// 128 random bits as hex, for the URL.
std::string makeToken();

} // namespace binocle::viewer
