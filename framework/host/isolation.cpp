// SPDX-License-Identifier: MIT
// Plugins out of process: examination in children, and the host's side of the helper
// process that runs an isolated plugin (its side is helper_side.cpp).
#include "host/isolation.hpp"

#include "core/error.hpp"
#include "core/log.hpp"

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
#include <mutex>

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

// ---- The helper executable ------------------------------------------------------------------

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

namespace {

size_t pageAligned(size_t n) {
    const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
    return (n + page - 1) / page * page;
}

// Raised by PluginHelper::call when the helper crashed, or was killed by the watchdog.
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

// ---- PluginHelper (the host's side) ---------------------------------------------------------

struct PluginHelper::Reply {
    int32_t rc = 0;
    std::string message;
    helper::Reader payload;
};

PluginHelper::PluginHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host, std::string lost)
    : record_(record), params_(params), options_(params.isolation()), host_(host), lost_what_(std::move(lost)) {}

PluginHelper::~PluginHelper() { stopHelper(); }

void PluginHelper::spawn() {
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

void PluginHelper::launch() {
    spawn();
    // create includes starting the helper (exec, dynamic loading): on a busy machine that
    // alone can take seconds, so it gets at least kStartMs whatever call_timeout_ms says.
    constexpr int32_t kStartMs = 15000;
    call("create", helper::kCreate, helper::Writer().put<int32_t>(record_.kind).data() + helper::encodeParams(params_),
         nullptr, options_.call_timeout_ms > 0 ? std::max(options_.call_timeout_ms, kStartMs) : 0,
         "call_timeout_ms, at least 15000 ms for the helper to start");
}

void PluginHelper::stopHelper() {
    if (socket_ >= 0) {
        // The instance is destroyed in the helper while we listen: what it logs then
        // still reaches the log.
        try {
            const int32_t limit = options_.call_timeout_ms > 0 ? std::min(options_.call_timeout_ms, 2000) : 2000;
            call("destroy", helper::kDestroy, {}, nullptr, limit);
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

PluginHelper::Reply PluginHelper::call(const char *what, uint32_t op, const std::string &payload, SharedRegion *region,
                                       int32_t timeout_ms, const char *limit) {
    const std::string who = std::string(kindName(record_.kind)) + " plugin '" + record_.name + "' (" + record_.path + "): " + what;
    if (socket_ < 0)
        throw HelperGone{who + ": its helper process is gone" + (gone_.empty() ? "" : " (" + gone_ + ")"), BINOCLE_ERR_INTERNAL};
    helper::Writer w;
    w.put<uint32_t>(op);
    int fd = -1;
    if (region) {
        w.put<uint32_t>(region->id()).put<uint64_t>(region->size());
        if (region->sentTo != generation_) fd = region->fd();
    } else {
        w.put<uint32_t>(helper::kNoRegion).put<uint64_t>(0);
    }
    w.raw(payload);
    Reply r = exchange(who, w.data(), fd, timeout_ms < 0 ? options_.call_timeout_ms : timeout_ms,
                       limit ? limit : "call_timeout_ms");
    if (region) region->sentTo = generation_;
    if (r.rc != BINOCLE_OK) throw PluginError(r.message, r.rc);
    return r;
}

PluginHelper::Reply PluginHelper::exchange(const std::string &who, const std::string &request, int fd, int32_t timeout_ms,
                                           const std::string &limit) {
    auto gone = [&](const std::string &how) -> HelperGone {
        ::close(socket_);
        socket_ = -1;
        pid_ = -1;
        gone_ = who.substr(who.rfind(": ") + 2) + " " + how;
        return HelperGone{who + " " + how, BINOCLE_ERR_INTERNAL};
    };
    const bool sent = helper::sendMessage(socket_, request, fd);
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
        if (!helper::receiveMessage(socket_, msg, nullptr)) break;
        try {
            helper::Reader r(msg);
            const auto type = r.get<uint32_t>();
            if (type == helper::kReply) {
                Reply reply;
                reply.rc = r.get<int32_t>();
                reply.message = r.str();
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

void PluginHelper::dispatch(uint32_t type, helper::Reader &r) {
    if (type == helper::kLog) {
        const auto origin = r.get<uint8_t>();
        const auto level = r.get<int32_t>();
        const std::string text = r.str();
        if (origin == helper::kFromHelper) spdlog::log(spdlogLevel(level), "{}", text);
        else if (host_ && host_->log) host_->log(host_->context, level, text.c_str());
        else logFromPlugin(record_.name, level, text);
    } else if (type == helper::kMetric) {
        const std::string name = r.str();
        const auto value = r.get<double>();
        const std::string unit = r.str();
        if (host_ && host_->report_metric) host_->report_metric(host_->context, name.c_str(), value, unit.c_str());
    } else if (type == helper::kText) {
        const std::string name = r.str();
        const std::string text = r.str();
        if (host_ && host_->report_text) host_->report_text(host_->context, name.c_str(), text.c_str());
    } else {
        throw Error("a message of unknown type " + std::to_string(type));
    }
}

void PluginHelper::launchOrThrow() {
    try {
        launch();
    } catch (const HelperGone &g) {
        throw PluginError(g.what, g.code);
    }
}

bool PluginHelper::guarded(const std::function<void()> &attempt) {
    try {
        attempt();
        return true;
    } catch (const HelperGone &g) {
        recover(g.what);
        return false;
    }
}

void PluginHelper::recover(const std::string &gone) {
    std::string why = gone;
    for (;;) {
        if (!options_.restart || restarts_ >= options_.max_restarts) {
            if (options_.restart)
                why += "; not restarted: " + std::to_string(restarts_) + " restart(s) already (max_restarts)";
            throw PluginError(why, BINOCLE_ERR_INTERNAL);
        }
        ++restarts_;
        spdlog::warn("{}; restarting its helper ({} of {}); {}", why, restarts_, options_.max_restarts, lost_what_);
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
    struct Describer : PluginHelper {
        Describer(const PluginRecord &r) : PluginHelper(r, ParamValues(), nullptr, "") {}
    } d(file);
    try {
        d.spawn();
        auto r = d.call("load", helper::kDescribe, {}, nullptr, timeout_ms, "the time a load may take");
        return helper::decodeDescription(r.payload, path);
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

// ---- Matcher ----------------------------------------------------------------------------------

MatcherHelper::MatcherHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host)
    : PluginHelper(record, params, host, "this frame has no disparity"), shared_(record.name, 0) {
    launchOrThrow();
}

MatcherHelper::~MatcherHelper() = default;

void MatcherHelper::compute(const cv::Mat &left, const cv::Mat &right, cv::Mat &disparity) {
    const size_t rowBytes = left.cols * left.elemSize();
    const size_t imageBytes = pageAligned(rowBytes * left.rows);
    const size_t dispBytes = pageAligned(static_cast<size_t>(left.cols) * left.rows * sizeof(float));
    const bool done = guarded([&] {
        uint8_t *base = shared_.reserve(2 * imageBytes + dispBytes);
        // The one copy of the pixels: into the shared mapping the helper reads.
        left.copyTo(cv::Mat(left.size(), left.type(), base, rowBytes));
        right.copyTo(cv::Mat(right.size(), right.type(), base + imageBytes, rowBytes));
        helper::Writer w;
        w.put<int32_t>(left.cols).put<int32_t>(left.rows).put<int32_t>(left.type()).put<uint64_t>(imageBytes);
        call("compute", helper::kCompute, w.data(), &shared_);
        cv::Mat(left.size(), CV_32F, base + 2 * imageBytes).copyTo(disparity);
    });
    if (!done) disparity.setTo(cv::Scalar(BINOCLE_INVALID_DISPARITY));
}

std::pair<int32_t, int32_t> MatcherHelper::disparityRange() {
    std::pair<int32_t, int32_t> range{0, 0};
    while (!guarded([&] {
        Reply r = call("disparity_range", helper::kRange);
        range.first = r.payload.get<int32_t>();
        range.second = r.payload.get<int32_t>();
    })) {
    }
    return range;
}

// ---- Source ----------------------------------------------------------------------------------

// Shared regions that frames are copied into, one per frame lent at a time. A slot stays
// busy while its LentFrame lives (on any thread); then the next grab may reuse it.
struct SourceHelper::Slots {
    std::string name;
    std::mutex mutex;
    std::vector<std::unique_ptr<SharedRegion>> regions;
    std::vector<bool> busy;
    SharedRegion &take(size_t &index) {
        std::lock_guard<std::mutex> lock(mutex);
        for (index = 0; index < busy.size() && busy[index]; ++index) {
        }
        if (index == busy.size()) {
            regions.push_back(std::make_unique<SharedRegion>(name, static_cast<uint32_t>(index)));
            busy.push_back(false);
        }
        busy[index] = true;
        return *regions[index];
    }
    void give(size_t index) {
        std::lock_guard<std::mutex> lock(mutex);
        busy[index] = false;
    }
};

namespace {

// What a LentFrame of an isolated source holds: its slot, the names and texts.
struct FrameCopy {
    std::function<void()> release;
    std::vector<binocle_named_image> extras;
    std::deque<std::string> names;
    std::string metadata;
    ~FrameCopy() {
        if (release) release();
    }
};

} // namespace

SourceHelper::SourceHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host)
    : PluginHelper(record, params, host, "that grab is lost; the source is created (and started) again"),
      slots_(std::make_shared<Slots>()) {
    slots_->name = record.name;
    launchOrThrow();
}

SourceHelper::~SourceHelper() = default;

void SourceHelper::afterRestart() {
    if (started_) call("start", helper::kStart);
}

void SourceHelper::start() {
    while (!guarded([&] { call("start", helper::kStart); })) {
    }
    started_ = true;
}

void SourceHelper::stop() {
    started_ = false; // a restart during stop leaves the new instance stopped
    guarded([&] { call("stop", helper::kStop); });
}

std::unique_ptr<LentFrame> SourceHelper::grab(int32_t timeout_ms) {
    // The grab may wait timeout_ms by itself: the watchdog starts after that.
    const int32_t watchdog = options().call_timeout_ms > 0 ? options().call_timeout_ms + std::max(timeout_ms, 0) : 0;
    const std::string limitText = "its wait of " + std::to_string(timeout_ms) + " ms + call_timeout_ms";
    size_t slot = 0;
    SharedRegion &region = slots_->take(slot);
    auto copy = std::make_shared<FrameCopy>();
    auto slots = slots_;
    copy->release = [slots, slot] { slots->give(slot); };
    std::unique_ptr<LentFrame> out;
    try {
        while (!guarded([&] {
            for (;;) {
                helper::Writer w;
                w.put<int32_t>(timeout_ms);
                Reply r = call("grab", helper::kGrab, w.data(), &region, watchdog, limitText.c_str());
                const auto need = r.payload.get<uint64_t>();
                if (need > region.size()) {
                    region.reserve(need); // the helper keeps the frame until it fits
                    continue;
                }
                binocle_stereo_frame f{};
                f.struct_size = sizeof f;
                f.sequence = r.payload.get<uint64_t>();
                f.timestamp_left_ns = r.payload.get<int64_t>();
                f.timestamp_right_ns = r.payload.get<int64_t>();
                f.left = helper::getImage(r.payload, region.data(), region.size());
                f.right = helper::getImage(r.payload, region.data(), region.size());
                const auto extras = r.payload.get<int32_t>();
                if (extras < 0 || extras > 64) throw Error("malformed frame from the plugin helper");
                for (int32_t i = 0; i < extras; ++i) {
                    copy->names.push_back(r.payload.str());
                    binocle_named_image e{};
                    e.name = copy->names.back().c_str();
                    e.image = helper::getImage(r.payload, region.data(), region.size());
                    copy->extras.push_back(e);
                }
                f.extras = copy->extras.empty() ? nullptr : copy->extras.data();
                f.extra_count = extras;
                const auto [hasMetadata, metadata] = r.payload.cstr();
                copy->metadata = metadata;
                f.metadata = hasMetadata ? copy->metadata.c_str() : nullptr;
                out = std::make_unique<LentFrame>(copy, f);
                return;
            }
        })) {
        }
    } catch (const PluginError &e) {
        if (e.code() == BINOCLE_ERR_END_OF_STREAM) return nullptr;
        throw;
    }
    return out;
}

std::string SourceHelper::calibration() {
    std::string text;
    while (!guarded([&] { text = call("calibration", helper::kCalibration).payload.str(); })) {
    }
    return text;
}

std::string SourceHelper::statistics() {
    std::string text;
    while (!guarded([&] { text = call("statistics", helper::kStatistics).payload.str(); })) {
    }
    return text;
}

// ---- Transform --------------------------------------------------------------------------------

namespace {

// A cloud's arrays in a Layout, and their description for the helper.
void placeCloud(const binocle_cloud &c, helper::Layout &layout, helper::Writer &w) {
    const uint64_t n = static_cast<uint64_t>(std::max<int64_t>(c.count, 0));
    w.put<int64_t>(c.count).put<int32_t>(c.image_width).put<int32_t>(c.image_height).put<int32_t>(c.frame);
    w.put<uint64_t>(layout.placeArray(c.xyz, 3 * n * sizeof(float)));
    w.put<uint8_t>(c.rgb != nullptr).put<uint64_t>(c.rgb ? layout.placeArray(c.rgb, 3 * n) : 0);
    w.put<uint8_t>(c.pixel != nullptr).put<uint64_t>(c.pixel ? layout.placeArray(c.pixel, n * sizeof(int32_t)) : 0);
}

} // namespace

TransformHelper::TransformHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host)
    : PluginHelper(record, params, host, "this frame's cloud is dropped"), shared_(record.name, 0) {
    launchOrThrow();
}

TransformHelper::~TransformHelper() = default;

void TransformHelper::apply(binocle_cloud &cloud) {
    helper::Layout layout;
    helper::Writer w;
    placeCloud(cloud, layout, w);
    const bool done = guarded([&] {
        uint8_t *base = shared_.reserve(layout.bytes());
        layout.copyInto(base);
        Reply r = call("apply", helper::kApply, w.data(), &shared_);
        const auto count = r.payload.get<int64_t>();
        const auto frame = r.payload.get<int32_t>();
        const auto xyz = r.payload.get<uint64_t>(), rgb = r.payload.get<uint64_t>(), pixel = r.payload.get<uint64_t>();
        if (count < 0 || count > cloud.count) throw Error("malformed cloud from the plugin helper");
        const uint64_t n = static_cast<uint64_t>(count);
        // Back into the host's own arrays: the transform may have compacted them.
        std::memcpy(cloud.xyz, helper::arrayAt(xyz, 3 * n * sizeof(float), base, shared_.size()), 3 * n * sizeof(float));
        if (cloud.rgb) std::memcpy(cloud.rgb, helper::arrayAt(rgb, 3 * n, base, shared_.size()), 3 * n);
        if (cloud.pixel)
            std::memcpy(cloud.pixel, helper::arrayAt(pixel, n * sizeof(int32_t), base, shared_.size()), n * sizeof(int32_t));
        cloud.count = count;
        cloud.frame = frame;
    });
    if (!done) cloud.count = 0;
}

// ---- Evaluator --------------------------------------------------------------------------------

EvaluatorHelper::EvaluatorHelper(const PluginRecord &record, const ParamValues &params, const binocle_host *host)
    : PluginHelper(record, params, host, "this frame has no figures from it, and its totals start again"),
      shared_(record.name, 0) {
    launchOrThrow();
}

EvaluatorHelper::~EvaluatorHelper() = default;

void EvaluatorHelper::evaluate(const binocle_eval_input &in) {
    helper::Layout layout;
    helper::Writer w;
    auto image = [&](const binocle_image *im) {
        w.put<uint8_t>(im != nullptr);
        if (im) helper::putImage(w, layout.place(*im));
    };
    w.put<uint8_t>(in.frame != nullptr);
    if (const binocle_stereo_frame *f = in.frame) {
        w.put<uint64_t>(f->sequence).put<int64_t>(f->timestamp_left_ns).put<int64_t>(f->timestamp_right_ns);
        helper::putImage(w, layout.place(f->left));
        helper::putImage(w, layout.place(f->right));
        w.put<int32_t>(f->extra_count);
        for (int32_t i = 0; i < f->extra_count; ++i) {
            w.str(f->extras[i].name ? f->extras[i].name : "");
            helper::putImage(w, layout.place(f->extras[i].image));
        }
        w.cstr(f->metadata);
    }
    image(in.rectified_left);
    image(in.rectified_right);
    image(in.disparity);
    w.put<uint8_t>(in.cloud != nullptr);
    if (in.cloud) placeCloud(*in.cloud, layout, w);
    // The calibration and the rig change rarely: sent again only when they did.
    const bool fresh = sentGeneration_ != generation();
    auto text = [&](const char *t, std::string &sent, bool &sentNull) {
        const bool same = !fresh && (t == nullptr) == sentNull && (!t || sent == t);
        w.put<uint8_t>(same);
        if (same) return;
        w.cstr(t);
        sent = t ? t : "";
        sentNull = t == nullptr;
    };
    text(in.calibration_yaml, sentCalibration_, sentCalibrationNull_);
    text(in.rig_yaml, sentRig_, sentRigNull_);
    w.cstr(in.output_dir);
    w.put<int32_t>(in.min_disparity).put<int32_t>(in.num_disparities).put<int32_t>(in.ground_pose_known);
    w.put<double>(in.camera_height_mm).put<double>(in.inclination_deg);
    const bool done = guarded([&] {
        layout.copyInto(shared_.reserve(layout.bytes()));
        call("evaluate", helper::kEvaluate, w.data(), &shared_);
        sentGeneration_ = generation();
    });
    (void)done; // after a restart the frame has no figures from this evaluator (a warning said so)
}

void EvaluatorHelper::finish() {
    guarded([&] { call("finish", helper::kFinish); });
}

} // namespace binocle
