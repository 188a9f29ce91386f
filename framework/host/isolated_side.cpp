// SPDX-License-Identifier: MIT
// The isolated side of `isolation: process`: binocle-plugin-helper loads one plugin file,
// serves its instance over the socket (each kind's calls by its ServedInstance), and
// forwards what it logs, prints and reports.
#include "host/isolated_side.hpp"
#include "host/ipc_transport.hpp"
#include "host/isolation.hpp"
#include "host/plugin_kinds.hpp"

#include "core/log.hpp"

#include <cerrno>
#include <csignal>
#include <fcntl.h>
#include <map>
#include <mutex>
#include <poll.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <thread>
#include <unistd.h>

namespace binocle {

namespace {

using namespace wire;

// The socket to the host; the plugin's own threads may log while a call is served.
std::mutex g_sendMutex;
int g_socket = -1;

bool send(const std::string &msg) {
    std::lock_guard<std::mutex> lock(g_sendMutex);
    return sendMessage(g_socket, msg);
}

void sendLog(LogOrigin origin, int32_t level, const std::string &text) { send(encode(LogMessage{origin, level, text})); }

// The helper's own spdlog lines (they name the plugin already) go to the host's log.
class ForwardSink : public spdlog::sinks::base_sink<std::mutex> {
protected:
    void sink_it_(const spdlog::details::log_msg &msg) override {
        int32_t level = BINOCLE_LOG_ERROR;
        if (msg.level <= spdlog::level::debug) level = BINOCLE_LOG_DEBUG;
        else if (msg.level == spdlog::level::info) level = BINOCLE_LOG_INFO;
        else if (msg.level == spdlog::level::warn) level = BINOCLE_LOG_WARNING;
        sendLog(kFromHelper, level, std::string(msg.payload.data(), msg.payload.size()));
    }
    void flush_() override {}
};

// What the plugin writes to stdout (info) and stderr (warning) reaches the host's log as
// lines tagged with the plugin, not as raw bytes on Binocle's terminal. A thread forwards
// what comes while the helper waits; drain() forwards what a call wrote before its reply
// goes out, so that the host sees a call's lines during that call, a last line without
// its newline included (after the last call the host closes the socket: nothing written
// later could reach it).
class OutputForwarder {
public:
    OutputForwarder() {
        int out[2], err[2];
        if (::pipe2(out, O_CLOEXEC | O_NONBLOCK) != 0) return;
        if (::pipe2(err, O_CLOEXEC | O_NONBLOCK) != 0) {
            ::close(out[0]);
            ::close(out[1]);
            return;
        }
        // The write ends block like a terminal would; only our reads must not.
        for (int w : {out[1], err[1]}) ::fcntl(w, F_SETFL, ::fcntl(w, F_GETFL) & ~O_NONBLOCK);
        std::fflush(nullptr);
        ::dup2(out[1], 1);
        ::dup2(err[1], 2);
        ::close(out[1]);
        ::close(err[1]);
        fds_[0] = out[0];
        fds_[1] = err[0];
        thread_ = std::thread([this] { run(); });
    }
    // Points stdout and stderr elsewhere (the pipes' last writers) and waits for the last
    // lines to go out.
    ~OutputForwarder() {
        if (!thread_.joinable()) return;
        std::fflush(nullptr);
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        ::dup2(null, 1);
        ::dup2(null, 2);
        ::close(null);
        thread_.join();
        for (int fd : fds_)
            if (fd >= 0) ::close(fd);
    }
    void drain() {
        if (!thread_.joinable()) return;
        std::fflush(nullptr);
        std::lock_guard<std::mutex> lock(mutex_);
        for (int i = 0; i < 2; ++i) readAvailable(i, true);
    }

private:
    // Reads what the pipe holds; sends whole lines (and the rest at end of file, or when
    // `rest`). Returns false at end of file. Holds mutex_.
    bool readAvailable(int i, bool rest) {
        bool open = true;
        for (;;) {
            char buf[4096];
            const ssize_t n = ::read(fds_[i], buf, sizeof buf);
            if (n > 0) {
                pending_[i].append(buf, static_cast<size_t>(n));
                continue;
            }
            if (n < 0 && errno == EINTR) continue;
            open = n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
            break;
        }
        for (size_t nl; (nl = pending_[i].find('\n')) != std::string::npos || ((!open || rest) && !pending_[i].empty());) {
            const std::string line = pending_[i].substr(0, nl);
            pending_[i].erase(0, nl == std::string::npos ? std::string::npos : nl + 1);
            sendLog(kFromOutput, i == 0 ? BINOCLE_LOG_INFO : BINOCLE_LOG_WARNING, line);
        }
        return open;
    }
    void run() {
        pollfd fds[2] = {{fds_[0], POLLIN, 0}, {fds_[1], POLLIN, 0}};
        while (fds[0].fd >= 0 || fds[1].fd >= 0) {
            if (::poll(fds, 2, -1) < 0) {
                if (errno == EINTR) continue;
                break;
            }
            std::lock_guard<std::mutex> lock(mutex_);
            for (int i = 0; i < 2; ++i)
                if (fds[i].fd >= 0 && (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) && !readAvailable(i, false))
                    fds[i].fd = -1; // end of file: stop polling it
        }
    }
    int fds_[2] = {-1, -1};
    std::string pending_[2];
    std::mutex mutex_;
    std::thread thread_;
};

// A host's region, mapped here.
struct Mapping {
    void *data = nullptr;
    size_t bytes = 0;
    ~Mapping() {
        if (data) ::munmap(data, bytes);
    }
    uint8_t *base() const { return static_cast<uint8_t *>(data); }
};

// The instance, its load error, and the host's regions mapped here.
struct Served {
    const PluginRecord *record = nullptr;
    std::string loadError;
    std::unique_ptr<ServedInstance> instance;
    std::map<uint32_t, Mapping> regions;

    Mapping &region(uint32_t id, uint64_t bytes, int fd) {
        Mapping &m = regions[id];
        if (fd >= 0) {
            if (m.data) ::munmap(m.data, m.bytes);
            m.data = nullptr;
            m.bytes = 0;
            void *p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
            const int mapErrno = errno; // before close() may change it
            ::close(fd);
            if (p == MAP_FAILED)
                throw Error("helper: cannot map " + std::to_string(bytes) + " bytes of shared memory: " + std::strerror(mapErrno));
            m.data = p;
            m.bytes = bytes;
        }
        return m;
    }
};

HostSink forwardingSink() {
    HostSink sink;
    sink.log = [](int32_t level, const std::string &text) { sendLog(kFromPlugin, level, text); };
    sink.metric = [](const std::string &name, double value, const std::string &unit) {
        send(encode(MetricMessage{name, value, unit}));
    };
    sink.text = [](const std::string &name, const std::string &text) { send(encode(TextMessage{name, text})); };
    return sink;
}

void create(Served &s, Reader &r) {
    auto [kind, params] = getCreate(r); // in this process: no isolation here
    if (s.record->kind != kind)
        throw Error("plugin file " + s.record->path + " is a " + kindName(s.record->kind) + " plugin now, not a " +
                    kindName(kind));
    s.instance.reset();
    s.instance = requireKind(kind).serve(*s.record, params, forwardingSink());
}

// One request: its reply's payload goes to `payload`.
void answer(Served &s, const std::string &msg, int &received, Writer &payload) {
    Reader r(msg);
    const RequestHead head = get<RequestHead>(r);
    if (head.op == kDestroy) {
        s.instance.reset();
        return;
    }
    if (!s.loadError.empty()) throw PluginError(s.loadError, BINOCLE_ERR_NOT_FOUND);
    static Mapping none;
    const Mapping &m = head.region == kNoRegion ? none : s.region(head.region, head.region_bytes, received);
    received = -1;
    if (head.op == kDescribe) return putDescription(payload, *s.record->table, s.record->params());
    if (head.op == kCreate) return create(s, r);
    if (head.op < kFirstKindOp) throw Error("helper: unknown request " + std::to_string(head.op));
    if (!s.instance) throw Error("helper: a call before create");
    s.instance->call(head.op, r, {m.base(), m.bytes}, payload);
}

} // namespace

int serveIsolatedPlugin(int fd, const std::string &path) {
    // The host may die first: a write to its socket must fail, not kill us silently.
    ::signal(SIGPIPE, SIG_IGN);
    g_socket = fd;
    auto logger = std::make_shared<spdlog::logger>("helper", std::make_shared<ForwardSink>());
    logger->set_level(spdlog::level::trace); // the host's logger chooses what it shows
    spdlog::set_default_logger(logger);
    OutputForwarder output;

    Served s;
    PluginHost host(std::vector<std::string>{});
    try {
        s.record = &host.load(path); // the library's constructors run here, never in Binocle
    } catch (const std::exception &e) {
        s.loadError = e.what();
    }
    std::string msg;
    int received = -1;
    while (receiveMessage(fd, msg, &received)) {
        int32_t rc = BINOCLE_OK;
        std::string message;
        Writer payload;
        try {
            answer(s, msg, received, payload);
        } catch (const PluginError &e) {
            rc = e.code();
            message = e.what();
        } catch (const std::exception &e) {
            rc = BINOCLE_ERR_INTERNAL;
            message = e.what();
        }
        if (received >= 0) ::close(received);
        received = -1;
        output.drain();
        if (!send(encodeReply(rc, message, payload.data()))) break;
    }
    s.instance.reset();
    s.regions.clear();
    return 0;
}

} // namespace binocle
