// SPDX-License-Identifier: MIT
// The proxy: the host's end of a plugin instance that runs in a helper process (spawn,
// calls with a watchdog, restarts), its shared memory, and files described by a helper
// process. The other end is isolated_side.cpp; what crosses is the ipc_*.hpp
// messages and the kinds' own (kind_<name>_messages.hpp).
#include "host/isolation.hpp"

#include "core/error.hpp"
#include "core/log.hpp"
#include "host/child_process.hpp"
#include "host/install_prefix.hpp"
#include "host/ipc_transport.hpp"
#include "host/plugin_kinds.hpp"

#include <algorithm>
#include <boost/dll/runtime_symbol_info.hpp>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <poll.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

namespace fs = std::filesystem;

namespace binocle {

namespace {

using Clock = std::chrono::steady_clock;

int remainingMs(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return left > 0 ? static_cast<int>(left) : 0;
}

} // namespace

// ---- The helper executable ------------------------------------------------------------------

std::string helperExecutable() {
    if (const char *env = std::getenv("BINOCLE_PLUGIN_HELPER"); env && *env) {
        if (fs::path(env).is_relative()) throw Error(std::string("BINOCLE_PLUGIN_HELPER=") + env + ": expected an absolute path");
        return env;
    }
    std::error_code ec;
    const fs::path prefix = installPrefix();
    const fs::path installed = prefix / "libexec/binocle/binocle-plugin-helper";
    if (!prefix.empty() && fs::exists(installed, ec)) return installed.lexically_normal().string();
    if (installPrefixIsSet())
        throw Error("the plugin helper (binocle-plugin-helper) is not installed under " + prefix.string() +
                    " (expected " + installed.string() + "); set BINOCLE_PLUGIN_HELPER to its path");
    const fs::path exe = boost::dll::program_location().string();
    const fs::path beside = exe.parent_path() / "binocle-plugin-helper";
    if (fs::exists(beside, ec)) return beside.lexically_normal().string();
    throw Error("the plugin helper (binocle-plugin-helper) is not installed next to " + exe.string() +
                " (expected in ../libexec/binocle/); set BINOCLE_PLUGIN_HELPER to its path");
}

size_t pageAligned(size_t n) {
    const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
    return (n + page - 1) / page * page;
}

namespace {

// Raised by PluginProxy::call when the helper crashed, or was killed by the watchdog.
struct HelperGone {
    std::string what;
    int32_t code;
};

spdlog::level::level_enum spdlogLevel(int32_t level) {
    if (level <= BINOCLE_LOG_DEBUG) return spdlog::level::debug;
    if (level == BINOCLE_LOG_INFO) return spdlog::level::info;
    if (level == BINOCLE_LOG_WARNING) return spdlog::level::warn;
    return spdlog::level::err;
}

} // namespace

// ---- SharedRegion ---------------------------------------------------------------------------

SharedRegion::~SharedRegion() {
    if (data_) ::munmap(data_, bytes_);
    if (fd_ >= 0) ::close(fd_);
}

uint8_t *SharedRegion::reserve(size_t bytes) {
    bytes = std::max<size_t>(bytes, 1);
    if (bytes <= bytes_) return data();
    if (data_) ::munmap(data_, bytes_);
    if (fd_ >= 0) ::close(fd_);
    data_ = nullptr;
    bytes_ = 0;
    sentTo = 0;
    const size_t size = pageAligned(bytes);
    fd_ = ::memfd_create(("binocle-" + name_).c_str(), MFD_CLOEXEC);
    if (fd_ < 0 || ::ftruncate(fd_, static_cast<off_t>(size)) != 0)
        throw Error(std::string("cannot create shared memory for the plugin helper: ") + std::strerror(errno));
    void *p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
    if (p == MAP_FAILED) throw Error(std::string("cannot map shared memory for the plugin helper: ") + std::strerror(errno));
    data_ = p;
    bytes_ = size;
    return data();
}

// ---- PluginProxy ---------------------------------------------------------

PluginProxy::PluginProxy(const PluginRecord &record, const ParamValues &params, const IsolationOptions &isolation,
                         const binocle_host *host)
    : record_(record), params_(params), options_(isolation), host_(host), kind_(pluginKind(record.kind)) {}

PluginProxy::~PluginProxy() { stopHelper(); }

void PluginProxy::spawn() {
    const std::string exe = helperExecutable();
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0)
        throw Error(std::string("cannot start a helper process: socketpair: ") + std::strerror(errno));
    // fd 3 in the helper. dup2 onto itself would keep close-on-exec: move off 3 first.
    int child = sv[1];
    if (child == 3) {
        child = ::fcntl(sv[1], F_DUPFD_CLOEXEC, 10);
        ::close(sv[1]);
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, child, 3);
    posix_spawn_file_actions_adddup2(&actions, 2, 1); // until the helper forwards its output
    std::vector<std::string> args = {exe, "--fd", "3", "--plugin", record_.path};
    std::vector<char *> argv;
    for (auto &a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = ::posix_spawn(&pid_, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(child);
    if (rc != 0) {
        ::close(sv[0]);
        pid_ = -1;
        throw Error("cannot start the plugin helper " + exe + ": " + std::strerror(rc));
    }
    socket_ = sv[0];
    ++generation_;
    gone_.clear();
}

void PluginProxy::launch() {
    spawn();
    // create includes starting the helper (exec, dynamic loading): on a busy machine that
    // alone can take seconds, so it gets at least kStartMs whatever call_timeout_ms says.
    constexpr int32_t kStartMs = 15000;
    wire::Writer create;
    wire::putCreate(create, record_.kind, params_);
    call(wire::kCreate, create.data(), nullptr, options_.call_timeout_ms > 0 ? std::max(options_.call_timeout_ms, kStartMs) : 0,
         "call_timeout_ms, at least 15000 ms for the helper to start");
}

void PluginProxy::stopHelper() {
    if (socket_ >= 0) {
        // The instance is destroyed in the helper while we listen: what it logs then
        // still reaches the log.
        try {
            const int32_t limit = options_.call_timeout_ms > 0 ? std::min(options_.call_timeout_ms, 2000) : 2000;
            call(wire::kDestroy, {}, nullptr, limit);
        } catch (...) {
        }
    }
    if (socket_ >= 0) {
        ::shutdown(socket_, SHUT_RDWR); // the helper exits
        ::close(socket_);
        socket_ = -1;
    }
    if (pid_ > 0) {
        int status = 0;
        const auto deadline = Clock::now() + std::chrono::milliseconds(1000);
        while (::waitpid(pid_, &status, WNOHANG) == 0) {
            if (Clock::now() > deadline) {
                killAndReap(pid_);
                break;
            }
            ::usleep(1000);
        }
        pid_ = -1;
    }
}

const char *PluginProxy::callName(uint32_t op) const {
    switch (op) {
    case wire::kDescribe: return "load";
    case wire::kCreate: return "create";
    case wire::kDestroy: return "destroy";
    default: return kind_ ? kind_->callName(op) : "call";
    }
}

PluginProxy::Reply PluginProxy::call(uint32_t op, const std::string &payload, SharedRegion *region, int32_t timeout_ms,
                                     const char *limit) {
    const std::string who =
        std::string(kindName(record_.kind)) + " plugin '" + record_.name + "' (" + record_.path + "): " + callName(op);
    if (socket_ < 0)
        throw HelperGone{who + ": its helper process is gone" + (gone_.empty() ? "" : " (" + gone_ + ")"), BINOCLE_ERR_INTERNAL};
    wire::RequestHead head;
    head.op = op;
    int fd = -1;
    if (region) {
        head.region = region->id();
        head.region_bytes = region->size();
        if (region->sentTo != generation_) fd = region->fd();
    }
    wire::Writer w;
    wire::put(w, head);
    w.raw(payload);
    Reply r = exchange(who, w.data(), fd, timeout_ms < 0 ? options_.call_timeout_ms : timeout_ms,
                       limit ? limit : "call_timeout_ms");
    if (region) region->sentTo = generation_;
    if (r.rc != BINOCLE_OK) throw PluginError(r.message, r.rc);
    return r;
}

PluginProxy::Reply PluginProxy::exchange(const std::string &who, const std::string &request, int fd, int32_t timeout_ms,
                                           const std::string &limit) {
    auto gone = [&](const std::string &how) -> HelperGone {
        ::close(socket_);
        socket_ = -1;
        pid_ = -1;
        gone_ = who.substr(who.rfind(": ") + 2) + " " + how;
        return HelperGone{who + " " + how, BINOCLE_ERR_INTERNAL};
    };
    const bool sent = wire::sendMessage(socket_, request, fd);
    const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    std::string msg;
    while (sent) {
        pollfd p{socket_, POLLIN, 0};
        const int n = ::poll(&p, 1, timeout_ms > 0 ? remainingMs(deadline) : -1);
        if (n < 0 && errno == EINTR) continue;
        if (n == 0) {
            killAndReap(pid_);
            throw gone("did not return within " + std::to_string(timeout_ms) + " ms (" + limit +
                       "); its helper process was killed (" + describeSignal(SIGKILL) + ")");
        }
        if (!wire::receiveMessage(socket_, msg, nullptr)) break;
        try {
            wire::Reader r(msg);
            const auto type = r.get<uint32_t>();
            if (type == wire::kReply) {
                const wire::ReplyHead head = wire::get<wire::ReplyHead>(r);
                Reply reply;
                reply.rc = head.rc;
                reply.message = head.message;
                reply.payload = std::move(r);
                return reply;
            }
            dispatch(type, r);
        } catch (const Error &e) {
            // Out of step with us (the plugin wrote on the helper's socket?): it cannot go on.
            killAndReap(pid_);
            throw gone(std::string("got an answer it could not read (") + e.what() + "); its helper process was killed");
        }
    }
    // End of stream: the helper died during the call (or closed its socket: it gets a
    // moment to exit, then it is killed).
    int status = 0;
    const auto grace = Clock::now() + std::chrono::milliseconds(2000);
    for (;;) {
        const pid_t done = ::waitpid(pid_, &status, WNOHANG);
        if (done == pid_ || (done < 0 && errno != EINTR)) break;
        if (Clock::now() > grace) {
            status = killAndReap(pid_);
            break;
        }
        ::usleep(1000);
    }
    throw gone("crashed in its helper process (" + describeExit(status) + ")");
}

void PluginProxy::dispatch(uint32_t type, wire::Reader &r) {
    if (type == wire::kLog) {
        const wire::LogMessage m = wire::get<wire::LogMessage>(r);
        if (m.origin == wire::kFromHelper) spdlog::log(spdlogLevel(m.level), "{}", m.text);
        else if (host_ && host_->log) host_->log(host_->context, m.level, m.text.c_str());
        else logFromPlugin(record_.name, m.level, m.text);
    } else if (type == wire::kMetric) {
        const wire::MetricMessage m = wire::get<wire::MetricMessage>(r);
        if (host_ && host_->report_metric) host_->report_metric(host_->context, m.name.c_str(), m.value, m.unit.c_str());
    } else if (type == wire::kText) {
        const wire::TextMessage m = wire::get<wire::TextMessage>(r);
        if (host_ && host_->report_text) host_->report_text(host_->context, m.name.c_str(), m.text.c_str());
    } else {
        throw Error("a message of unknown type " + std::to_string(type));
    }
}

void PluginProxy::launchOrThrow() {
    try {
        launch();
    } catch (const HelperGone &g) {
        throw PluginError(g.what, g.code);
    }
}

bool PluginProxy::guarded(const std::function<void()> &attempt) {
    try {
        attempt();
        return true;
    } catch (const HelperGone &g) {
        recover(g.what);
        return false;
    }
}

void PluginProxy::recover(const std::string &gone) {
    std::string why = gone;
    for (;;) {
        if (!options_.restart || restarts_ >= options_.max_restarts) {
            if (options_.restart)
                why += "; not restarted: " + std::to_string(restarts_) + " restart(s) already (max_restarts)";
            throw PluginError(why, BINOCLE_ERR_INTERNAL);
        }
        ++restarts_;
        spdlog::warn("{}; restarting its helper ({} of {}); {}", why, restarts_, options_.max_restarts, kind_ ? kind_->lostOnRestart : "");
        try {
            launch();
            afterRestart();
            ++lost_;
            return;
        } catch (const HelperGone &again) {
            why = again.what; // the fresh helper died too: that costs another restart
        }
    }
}

// ---- Description in a helper ----------------------------------------------------------------

PluginRecord describeInHelper(const std::string &path, int32_t timeout_ms) {
    // A helper with no instance: the record it serves is the file's name for messages.
    PluginRecord file;
    file.path = path;
    file.name = fs::path(path).stem().string();
    if (file.name.rfind("binocle_", 0) == 0) file.name = file.name.substr(8);
    struct Describer : PluginProxy {
        Describer(const PluginRecord &r) : PluginProxy(r, ParamValues(), IsolationOptions(), nullptr) {}
    } d(file);
    try {
        d.spawn();
        auto r = d.call(wire::kDescribe, {}, nullptr, timeout_ms, "the time a load may take");
        return wire::getDescription(r.payload, path);
    } catch (const HelperGone &g) {
        // "load crashed in its helper process (killed by signal 11 (SIGSEGV))": the code of
        // a library runs when it is loaded (constructors), before any check.
        throw Error(g.what.substr(g.what.rfind("): ") + 3) + "; a library's code runs when it is loaded");
    } catch (const PluginError &e) {
        // The helper's own load refused it: its words, without "plugin file X refused: ".
        std::string why = e.what();
        const std::string prefix = "plugin file " + path + " refused: ";
        if (why.rfind(prefix, 0) == 0) why = why.substr(prefix.size());
        throw Error(why);
    }
}

} // namespace binocle
