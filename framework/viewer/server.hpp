// SPDX-License-Identifier: MIT
// The viewer's web server (Boost.Beast): the embedded page over HTTP, frames and
// commands over WebSocket, on a loopback address, behind a token and a Host check.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace binocle::viewer {

// What a page sends once it has shown a frame: the server's flow control, so that a
// browser gets frames no faster than it can draw them.
inline constexpr const char *kShownMessage = R"({"op":"shown"})";

struct HttpReply {
    int status = 200;
    std::string content_type = "application/json";
    std::string body;
    std::string filename; // set: sent as an attachment (a download)
};

struct ServerHandlers {
    // Text message a browser gets when its WebSocket opens (the current state).
    std::function<std::string()> hello;
    // A command from a browser (WebSocket text or POST /api/command), JSON; the reply
    // goes back to that browser only. Runs on the server's thread: keep it short.
    std::function<std::string(const std::string &command)> command;
    // GET /api/<name> (token already checked); status 404 for unknown names.
    std::function<HttpReply(const std::string &name)> api;
    // Binary message a browser gets after `hello`: the last frame, if any.
    std::function<std::shared_ptr<const std::string>()> lastFrame;
};

class Server {
public:
    // Binds address:port (port 0: any free port) and serves on a thread of its own.
    // Throws binocle::Error naming the address when it cannot bind.
    Server(const std::string &address, uint16_t port, std::string token, ServerHandlers handlers);
    ~Server(); // stops and joins

    uint16_t port() const;
    const std::string &token() const;
    std::string url() const; // http://ADDRESS:PORT/?token=...

    // True when some browser has no frame waiting or being written and has shown the last
    // one (its page sends kShownMessage once it has): only then is a frame worth encoding.
    bool wantsFrame() const;
    size_t browsers() const;
    // Every browser gets the newest frame; one still sending an older frame gets this
    // one next, and the frames between are skipped (for that browser only).
    void broadcastFrame(std::shared_ptr<const std::string> binary);
    // Every browser gets this text (state changes, errors), in order.
    void broadcastText(const std::string &text);

    // Whether `host` (a Host header: "name[:port]") names this machine's loopback or the
    // bound address; requests naming anything else are refused (DNS rebinding).
    static bool isLocalHost(const std::string &host, const std::string &boundAddress);

    struct Impl;

private:
    std::shared_ptr<Impl> impl_;
};

// 128 random bits as hex, for the URL.
std::string makeToken();

} // namespace binocle::viewer
