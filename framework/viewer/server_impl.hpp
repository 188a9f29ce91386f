// SPDX-License-Identifier: MIT
// The server's insides, shared by server.cpp (accepting, the command thread) and
// sessions.cpp (one HTTP or WebSocket connection each); not for other modules.
#pragma once

#include "viewer/server.hpp"
#include "viewer/web_guard.hpp"

#include <boost/asio.hpp>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <set>
#include <thread>

namespace binocle::viewer {

namespace detail {

class WsSession;

// Held by every connection while it is open: the count behind the connection cap.
using ConnectionSlot = std::shared_ptr<void>;

// Texts (replies, errors) a browser has not read beyond these: it is gone or stuck; it is
// dropped. States and frames do not count: each supersedes the one before.
inline constexpr size_t kMaxQueuedTexts = 256;
inline constexpr size_t kMaxQueuedTextBytes = 4 << 20;
// Commands waiting for the command thread, all browsers together; more are answered
// "busy" at once.
inline constexpr size_t kMaxPendingCommands = 32;
// Longest request head (request line and headers).
inline constexpr uint32_t kMaxHeaderBytes = 8 * 1024;

// Creates the first HTTP session of an accepted connection (sessions.cpp).
void startHttpSession(boost::asio::ip::tcp::socket &&socket, std::shared_ptr<Server::Impl> server, ConnectionSlot slot);

} // namespace detail

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
    boost::asio::io_context io{1};
    boost::asio::ip::tcp::acceptor acceptor{io};
    boost::asio::steady_timer acceptRetry{io};
    std::chrono::milliseconds acceptBackoff{0};
    ServerOptions options;
    ServerHandlers handlers;
    size_t maxConnections = 0;
    std::atomic<size_t> connections{0};
    std::thread thread;
    std::atomic<bool> stopped{false};

    // Open WebSockets.
    mutable std::mutex mutex;
    std::set<std::shared_ptr<detail::WsSession>> sessions;

    // The command thread and what waits for it.
    struct Job {
        std::string text;
        std::function<void(std::string reply)> respond;
    };
    std::thread worker;
    std::mutex jobsMutex;
    std::condition_variable jobsCv;
    std::deque<Job> jobs;
    bool workerQuit = false;

    // What strangers can make the server log: a few lines per 10 s per kind.
    LogLimiter refusedLog{5, std::chrono::seconds(10)};
    LogLimiter connectionLog{5, std::chrono::seconds(10)};

    void accept();
    void acceptLater(const boost::system::error_code &ec);
    detail::ConnectionSlot takeSlot();
    // Queues a command for the command thread; `respond` is called once, from that
    // thread (or at once with a "busy" error).
    void submit(std::string text, std::function<void(std::string)> respond);
    void workLoop();

    void add(const std::shared_ptr<detail::WsSession> &s) {
        std::lock_guard<std::mutex> lock(mutex);
        sessions.insert(s);
    }
    void remove(const std::shared_ptr<detail::WsSession> &s) {
        std::lock_guard<std::mutex> lock(mutex);
        sessions.erase(s);
    }
    std::vector<std::shared_ptr<detail::WsSession>> snapshot() const {
        std::lock_guard<std::mutex> lock(mutex);
        return {sessions.begin(), sessions.end()};
    }
};

namespace detail {

// One browser's WebSocket: at most one frame and one state waiting, texts bounded.
class WsSession : public std::enable_shared_from_this<WsSession> {
public:
    virtual ~WsSession() = default;
    // From any thread.
    virtual void queueText(std::shared_ptr<const std::string> text) = 0;
    virtual void queueState(std::shared_ptr<const std::string> text) = 0;
    virtual void queueFrame(std::shared_ptr<const std::string> frame) = 0;
    virtual void close() = 0;
    // Nothing to write, and the page has shown the last frame (or took too long to say).
    virtual bool ready() const = 0;
};

} // namespace detail

} // namespace binocle::viewer
