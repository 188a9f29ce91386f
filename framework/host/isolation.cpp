// SPDX-License-Identifier: MIT
// Plugins out of process: examination in children, the matcher helper and its proxy.
#include "host/isolation.hpp"

#include "core/error.hpp"

#include <algorithm>
#include <boost/dll/runtime_symbol_info.hpp>
#include <cerrno>
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

std::string describeSignal(int sig) {
    const char *abbrev = sigabbrev_np(sig);
    return "signal " + std::to_string(sig) + (abbrev ? std::string(" (SIG") + abbrev + ")" : std::string());
}

std::string describeExit(int status) {
    if (WIFSIGNALED(status)) return "killed by " + describeSignal(WTERMSIG(status));
    if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
    return "ended (status " + std::to_string(status) + ")";
}

namespace {

using Clock = std::chrono::steady_clock;

int remainingMs(Clock::time_point deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    return left > 0 ? static_cast<int>(left) : 0;
}

// Kills and reaps a child; returns its wait status.
int killAndReap(pid_t pid) {
    ::kill(pid, SIGKILL);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

} // namespace

// ---- Examination in children ----------------------------------------------------------------

std::map<std::string, std::string> examineInChildren(const std::vector<std::string> &paths, int32_t timeout_ms) {
    struct Child {
        std::string path;
        pid_t pid = -1;
        int pipe = -1;
        std::string out;
        Clock::time_point deadline;
    };
    std::map<std::string, std::string> refusals;
    constexpr size_t kAtOnce = 8;
    size_t next = 0;
    std::vector<Child> running;
    std::fflush(nullptr); // nothing buffered may be written twice by a child
    while (next < paths.size() || !running.empty()) {
        while (next < paths.size() && running.size() < kAtOnce) {
            Child c;
            c.path = paths[next++];
            int fds[2];
            if (::pipe2(fds, O_CLOEXEC) != 0) {
                refusals[c.path] = std::string("cannot examine: pipe: ") + std::strerror(errno);
                continue;
            }
            c.pid = ::fork();
            if (c.pid == 0) {
                // The child: open the file with every check of the host, report, vanish.
                // Its own stdout goes to stderr so that a chatty constructor cannot garble
                // the parent's listing.
                ::close(fds[0]);
                ::dup2(2, 1);
                std::string reason;
                try {
                    PluginHost host(std::vector<std::string>{});
                    host.load(c.path);
                } catch (const std::exception &e) {
                    reason = e.what();
                    const std::string prefix = "plugin file " + c.path + " refused: ";
                    if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
                    if (reason.empty()) reason = "refused";
                }
                const char *p = reason.data();
                size_t left = reason.size();
                while (left > 0) {
                    ssize_t n = ::write(fds[1], p, left);
                    if (n <= 0) break;
                    p += n;
                    left -= static_cast<size_t>(n);
                }
                ::_exit(0);
            }
            ::close(fds[1]);
            if (c.pid < 0) {
                ::close(fds[0]);
                refusals[c.path] = std::string("cannot examine: fork: ") + std::strerror(errno);
                continue;
            }
            c.pipe = fds[0];
            c.deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
            running.push_back(std::move(c));
        }
        std::vector<pollfd> fds;
        int wait = timeout_ms;
        for (const auto &c : running) {
            fds.push_back({c.pipe, POLLIN, 0});
            wait = std::min(wait, remainingMs(c.deadline));
        }
        ::poll(fds.data(), fds.size(), wait);
        for (size_t i = 0; i < running.size();) {
            Child &c = running[i];
            bool done = false;
            if (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) {
                char buf[4096];
                ssize_t n = ::read(c.pipe, buf, sizeof buf);
                if (n > 0) c.out.append(buf, static_cast<size_t>(n));
                else done = true; // EOF: the child exited or died
            }
            if (done) {
                int status = 0;
                while (::waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
                }
                if (WIFSIGNALED(status))
                    refusals[c.path] = "crashed while loading (its code runs at load): " + describeExit(status);
                else if (!c.out.empty())
                    refusals[c.path] = c.out;
                else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
                    refusals[c.path] = "examination " + describeExit(status);
            } else if (remainingMs(c.deadline) == 0) {
                killAndReap(c.pid);
                refusals[c.path] = "still loading after " + std::to_string(timeout_ms) +
                                   " ms (a library constructor hangs?); its examination was killed";
                done = true;
            }
            if (done) {
                ::close(c.pipe);
                running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
                fds.erase(fds.begin() + static_cast<std::ptrdiff_t>(i));
            } else {
                ++i;
            }
        }
    }
    return refusals;
}

// ---- Messages between host and helper ------------------------------------------------------

namespace {

enum Op : uint32_t { kCreate = 1, kCompute = 2, kRange = 3 };
constexpr size_t kMaxMessage = 1 << 20;

class Writer {
public:
    template <class T>
    Writer &put(T v) {
        buf_.append(reinterpret_cast<const char *>(&v), sizeof v);
        return *this;
    }
    Writer &str(const std::string &s) {
        put<uint32_t>(static_cast<uint32_t>(s.size()));
        buf_ += s;
        return *this;
    }
    const std::string &data() const { return buf_; }

private:
    std::string buf_;
};

class Reader {
public:
    explicit Reader(std::string data) : data_(std::move(data)) {}
    template <class T>
    T get() {
        T v{};
        need(sizeof v);
        std::memcpy(&v, data_.data() + at_, sizeof v);
        at_ += sizeof v;
        return v;
    }
    std::string str() {
        const auto n = get<uint32_t>();
        need(n);
        std::string s = data_.substr(at_, n);
        at_ += n;
        return s;
    }

private:
    void need(size_t n) const {
        if (at_ + n > data_.size()) throw Error("malformed message between Binocle and its plugin helper");
    }
    std::string data_;
    size_t at_ = 0;
};

// Sends one message, with a file descriptor attached when fd >= 0. False when the peer
// is gone (no SIGPIPE: MSG_NOSIGNAL).
bool sendMessage(int sock, const std::string &msg, int fd = -1) {
    iovec iov{const_cast<char *>(msg.data()), msg.size()};
    msghdr h{};
    h.msg_iov = &iov;
    h.msg_iovlen = 1;
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
    if (fd >= 0) {
        h.msg_control = control;
        h.msg_controllen = sizeof control;
        cmsghdr *c = CMSG_FIRSTHDR(&h);
        c->cmsg_level = SOL_SOCKET;
        c->cmsg_type = SCM_RIGHTS;
        c->cmsg_len = CMSG_LEN(sizeof(int));
        std::memcpy(CMSG_DATA(c), &fd, sizeof fd);
    }
    ssize_t n;
    do {
        n = ::sendmsg(sock, &h, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n == static_cast<ssize_t>(msg.size());
}

// Receives one message; -1 in *fd when none came along. False at end of stream.
bool receiveMessage(int sock, std::string &msg, int *fd) {
    msg.resize(kMaxMessage);
    iovec iov{msg.data(), msg.size()};
    msghdr h{};
    h.msg_iov = &iov;
    h.msg_iovlen = 1;
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
    h.msg_control = control;
    h.msg_controllen = sizeof control;
    ssize_t n;
    do {
        n = ::recvmsg(sock, &h, MSG_CMSG_CLOEXEC);
    } while (n < 0 && errno == EINTR);
    if (n <= 0) return false;
    msg.resize(static_cast<size_t>(n));
    if (fd) {
        *fd = -1;
        for (cmsghdr *c = CMSG_FIRSTHDR(&h); c; c = CMSG_NXTHDR(&h, c))
            if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) std::memcpy(fd, CMSG_DATA(c), sizeof(int));
    }
    return true;
}

std::string encodeParams(const ParamValues &params) {
    Writer w;
    w.put<int32_t>(params.size());
    for (int32_t i = 0; i < params.size(); ++i) {
        const binocle_param &p = params.data()[i];
        w.str(p.name ? p.name : "").put<int32_t>(p.type).put<int64_t>(p.i).put<double>(p.d);
        w.put<uint8_t>(p.s != nullptr).str(p.s ? p.s : "").put<int32_t>(p.explicit_);
    }
    return w.data();
}

ParamValues decodeParams(Reader &r) {
    ParamValues values;
    const auto n = r.get<int32_t>();
    for (int32_t i = 0; i < n; ++i) {
        const std::string name = r.str();
        const auto type = r.get<int32_t>();
        const auto iv = r.get<int64_t>();
        const auto dv = r.get<double>();
        const bool hasText = r.get<uint8_t>() != 0;
        const std::string text = r.str();
        const bool isExplicit = r.get<int32_t>() != 0;
        if (hasText) values.setText(name, type, text, isExplicit);
        else if (type == BINOCLE_PARAM_DOUBLE) values.setDouble(name, dv, isExplicit);
        else if (type == BINOCLE_PARAM_BOOL) values.setBool(name, iv != 0, isExplicit);
        else values.setInt(name, iv, isExplicit);
    }
    return values;
}

size_t pageAligned(size_t n) {
    const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
    return (n + page - 1) / page * page;
}

// Raised inside MatcherHelper when the helper crashed or was killed.
struct HelperGone {
    std::string what;
    int32_t code;
};

} // namespace

std::string helperExecutable() {
    if (const char *env = std::getenv("BINOCLE_PLUGIN_HELPER"); env && *env) {
        if (fs::path(env).is_relative()) throw Error(std::string("BINOCLE_PLUGIN_HELPER=") + env + ": expected an absolute path");
        return env;
    }
    std::error_code ec;
    const fs::path exe = boost::dll::program_location().string();
    for (const fs::path &candidate : {exe.parent_path().parent_path() / "libexec/binocle/binocle-plugin-helper",
                                      exe.parent_path() / "binocle-plugin-helper"})
        if (fs::exists(candidate, ec)) return candidate.lexically_normal().string();
    throw Error("the plugin helper (binocle-plugin-helper) is not installed next to " + exe.string() +
                " (expected in ../libexec/binocle/); set BINOCLE_PLUGIN_HELPER to its path");
}

// ---- MatcherHelper (the host's side) --------------------------------------------------------

struct MatcherHelper::Reply {
    int32_t rc = 0;
    std::string message;
    Reader payload{std::string()};
};

MatcherHelper::MatcherHelper(const PluginRecord &record, const ParamValues &params)
    : record_(record), params_(params), options_(params.isolation()) {
    start();
}

MatcherHelper::~MatcherHelper() {
    stopHelper();
    if (shared_) ::munmap(shared_, sharedBytes_);
    if (memfd_ >= 0) ::close(memfd_);
}

void MatcherHelper::start() {
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
    posix_spawn_file_actions_adddup2(&actions, 2, 1); // plugin output never mixes with ours
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
    sharedSent_ = false;
    // create includes starting the helper (exec, dynamic loading): on a busy machine that
    // alone can take seconds, so it gets at least kStartMs whatever call_timeout_ms says.
    constexpr int32_t kStartMs = 15000;
    Reply r = call("create", Writer().put<uint32_t>(kCreate).data() + encodeParams(params_), -1,
                   options_.call_timeout_ms > 0 ? std::max(options_.call_timeout_ms, kStartMs) : 0);
    if (r.rc != BINOCLE_OK) throw PluginError(r.message, r.rc);
}

void MatcherHelper::stopHelper() {
    if (socket_ >= 0) {
        ::shutdown(socket_, SHUT_RDWR); // the helper destroys the instance and exits
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

MatcherHelper::Reply MatcherHelper::call(const std::string &what, const std::string &request, int fd, int32_t timeout_ms) {
    const std::string who = std::string(kindName(record_.kind)) + " plugin '" + record_.name + "' (" + record_.path + "): " + what;
    auto gone = [&](const std::string &how, int32_t code) -> HelperGone {
        ::close(socket_);
        socket_ = -1;
        pid_ = -1;
        return HelperGone{who + " " + how, code};
    };
    if (socket_ < 0) throw HelperGone{who + ": its helper process is gone", BINOCLE_ERR_INTERNAL};
    if (timeout_ms < 0) timeout_ms = options_.call_timeout_ms;
    const bool sent = sendMessage(socket_, request, fd);
    const auto deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
    std::string msg;
    if (sent) {
        for (;;) {
            pollfd p{socket_, POLLIN, 0};
            const int wait = timeout_ms > 0 ? remainingMs(deadline) : -1;
            const int n = ::poll(&p, 1, wait);
            if (n < 0 && errno == EINTR) continue;
            if (n == 0) {
                const int status = killAndReap(pid_);
                (void)status;
                throw gone("did not return within " + std::to_string(timeout_ms) +
                               " ms (call_timeout_ms); its helper process was killed (" + describeSignal(SIGKILL) + ")",
                           BINOCLE_ERR_TIMEOUT);
            }
            break;
        }
        if (receiveMessage(socket_, msg, nullptr)) {
            Reply r;
            Reader reader(msg);
            r.rc = reader.get<int32_t>();
            r.message = reader.str();
            r.payload = std::move(reader);
            return r;
        }
    }
    // End of stream: the helper died during the call.
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    throw gone("crashed in its helper process (" + describeExit(status) + ")", BINOCLE_ERR_INTERNAL);
}

void MatcherHelper::mapShared(size_t bytes) {
    if (bytes <= sharedBytes_) return;
    if (shared_) ::munmap(shared_, sharedBytes_);
    if (memfd_ >= 0) ::close(memfd_);
    shared_ = nullptr;
    memfd_ = ::memfd_create(("binocle-" + record_.name).c_str(), MFD_CLOEXEC);
    if (memfd_ < 0 || ::ftruncate(memfd_, static_cast<off_t>(bytes)) != 0)
        throw Error(std::string("cannot create shared memory for the plugin helper: ") + std::strerror(errno));
    void *p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, memfd_, 0);
    if (p == MAP_FAILED) throw Error(std::string("cannot map shared memory for the plugin helper: ") + std::strerror(errno));
    shared_ = p;
    sharedBytes_ = bytes;
    sharedSent_ = false;
}

void MatcherHelper::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    const size_t rowBytes = left.cols * left.elemSize();
    const size_t imageBytes = pageAligned(rowBytes * left.rows);
    const size_t dispBytes = pageAligned(static_cast<size_t>(left.cols) * left.rows * sizeof(float));
    try {
        if (socket_ < 0) throw HelperGone{"", BINOCLE_ERR_INTERNAL};
        mapShared(2 * imageBytes + dispBytes);
        auto *base = static_cast<uint8_t *>(shared_);
        // The one copy of the pixels: into the shared mapping the helper reads.
        left.copyTo(cv::Mat(left.size(), left.type(), base, rowBytes));
        right.copyTo(cv::Mat(right.size(), right.type(), base + imageBytes, rowBytes));
        Writer w;
        w.put<uint32_t>(kCompute).put<uint64_t>(sharedBytes_).put<int32_t>(left.cols).put<int32_t>(left.rows);
        w.put<int32_t>(left.type()).put<uint64_t>(imageBytes);
        Reply r = call("compute", w.data(), sharedSent_ ? -1 : memfd_);
        sharedSent_ = true;
        if (r.rc != BINOCLE_OK) throw PluginError(r.message, r.rc);
        cv::Mat(left.size(), CV_32F, base + 2 * imageBytes).copyTo(disparity);
    } catch (const HelperGone &g) {
        if (g.what.empty() || !options_.restart || restarts_ >= options_.max_restarts) {
            std::string msg = g.what.empty() ? "matcher plugin '" + record_.name + "': its helper process is gone" : g.what;
            if (options_.restart && !g.what.empty())
                msg += "; not restarted: " + std::to_string(restarts_) + " restart(s) already (max_restarts)";
            throw PluginError(msg, g.code);
        }
        ++restarts_;
        spdlog::warn("{}; restarting its helper ({} of {}); this frame has no disparity", g.what, restarts_,
                     options_.max_restarts);
        start();
        disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
    }
}

std::pair<int32_t, int32_t> MatcherHelper::disparityRange() {
    try {
        Reply r = call("disparity_range", Writer().put<uint32_t>(kRange).data());
        if (r.rc != BINOCLE_OK) throw PluginError(r.message, r.rc);
        const auto mn = r.payload.get<int32_t>();
        const auto num = r.payload.get<int32_t>();
        return {mn, num};
    } catch (const HelperGone &g) {
        throw PluginError(g.what, g.code);
    }
}

// ---- The helper's side --------------------------------------------------------------------

int serveIsolatedPlugin(int fd, const std::string &path) {
    // The host may die first: a write to its socket must fail, not kill us silently.
    ::signal(SIGPIPE, SIG_IGN);
    PluginHost host(std::vector<std::string>{});
    const PluginRecord *record = nullptr;
    std::string loadError;
    try {
        record = &host.load(path);
        if (record->kind != BINOCLE_KIND_MATCHER) loadError = "plugin file " + path + " is not a matcher";
    } catch (const std::exception &e) {
        loadError = e.what();
    }
    std::unique_ptr<Matcher> matcher;
    void *shared = nullptr;
    size_t sharedBytes = 0;
    std::string msg;
    int received = -1;
    while (receiveMessage(fd, msg, &received)) {
        Writer reply;
        int32_t rc = BINOCLE_OK;
        std::string message;
        Writer payload;
        try {
            Reader r(msg);
            const auto op = r.get<uint32_t>();
            if (!loadError.empty()) throw PluginError(loadError, BINOCLE_ERR_NOT_FOUND);
            if (op == kCreate) {
                matcher = std::make_unique<Matcher>(*record, decodeParams(r));
            } else if (op == kCompute) {
                if (!matcher) throw Error("compute before create");
                const auto bytes = r.get<uint64_t>();
                const auto width = r.get<int32_t>();
                const auto height = r.get<int32_t>();
                const auto type = r.get<int32_t>();
                const auto imageBytes = r.get<uint64_t>();
                if (received >= 0) {
                    if (shared) ::munmap(shared, sharedBytes);
                    shared = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, received, 0);
                    ::close(received);
                    received = -1;
                    if (shared == MAP_FAILED) {
                        shared = nullptr;
                        throw Error(std::string("helper: cannot map the shared images: ") + std::strerror(errno));
                    }
                    sharedBytes = bytes;
                }
                if (!shared || 2 * imageBytes + static_cast<size_t>(width) * height * sizeof(float) > sharedBytes)
                    throw Error("helper: images do not fit the shared memory");
                auto *base = static_cast<uint8_t *>(shared);
                cv::Mat left(height, width, type, base), right(height, width, type, base + imageBytes);
                cv::Mat disparity(height, width, CV_32F, base + 2 * imageBytes);
                disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
                matcher->computeInto(left, right, disparity);
            } else if (op == kRange) {
                if (!matcher) throw Error("disparity_range before create");
                const auto range = matcher->disparityRange();
                payload.put<int32_t>(range.first).put<int32_t>(range.second);
            } else {
                throw Error("helper: unknown request " + std::to_string(op));
            }
        } catch (const PluginError &e) {
            rc = e.code();
            message = e.what();
        } catch (const std::exception &e) {
            rc = BINOCLE_ERR_INTERNAL;
            message = e.what();
        }
        reply.put<int32_t>(rc).str(message);
        if (!sendMessage(fd, reply.data() + payload.data())) break;
    }
    matcher.reset();
    if (shared) ::munmap(shared, sharedBytes);
    return 0;
}

} // namespace binocle
