// SPDX-License-Identifier: MIT
// The live view: the pipeline (its stages in parallel), an encoder thread and the server
// thread. An observer on the writer stage copies a frame only when a browser is ready for
// one, the encoder is idle and the display rate allows; settings are validated like
// --set and applied between frames, the stages draining only while a change is pending.
#include "viewer/viewer.hpp"

#include "core/error.hpp"
#include "pipeline/pipeline.hpp"
#include "viewer/command.hpp"
#include "viewer/frame_snapshot.hpp"
#include "viewer/page_settings.hpp"
#include "viewer/server.hpp"
#include "viewer/settings_schema.hpp"
#include "viewer/web_guard.hpp"

#include <binocle/text.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle::viewer {

namespace {

using OJson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

std::string dumpJson(const OJson &j) { return j.dump(-1, ' ', false, OJson::error_handler_t::replace); }

// An error for the page: a message from the rig's validation or a plugin, escaped and cut
// (it may quote what a page sent).
OJson errorReply(const std::string &op, const std::string &message) {
    return {{"type", "error"}, {"op", op}, {"message", sdk::printable(message, 600)}};
}

// Refuses a non-loopback bind without --allow-remote; warns about what is allowed.
void checkExposure(const ViewOptions &options) {
    const std::string risk = remoteBindRisk(options.address);
    if (const std::string refusal = remoteBindRefusal(options.address, options.allow_remote); !refusal.empty())
        throw Error("view: " + refusal);
    if (!risk.empty()) spdlog::warn("view: {}", risk);
    if (::geteuid() == 0)
        spdlog::warn("view: running as root: whoever holds the page's token writes snapshots with root's rights; run binocle "
                     "view as an ordinary user");
}

class View {
public:
    View(const ViewOptions &options, const PluginHost &host) : options_(options), host_(host) {
        rig_ = loadRig(options.rig_file, options.overrides, host);
        page_ = std::make_unique<PageSettings>(rig_);
        paused_ = options.paused;
        step_ = options.paused; // paused from the start: one frame to look at
        updateWanted();
        if (options.display_fps > 0)
            minInterval_ = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.display_fps));
        if (options.cloud_fps > 0)
            cloudInterval_ = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.cloud_fps));
        encode_.grid = method::GridSpec{};
        encode_.max_cloud_points = options.cloud_points;
    }

    ViewSummary run(const std::function<void(const std::string &)> &listening) {
        ServerHandlers h;
        h.hello = [this] {
            cloudWanted_ = true; // a new page: its 3D view gets the next frame's cloud
            return dumpJson(state(true));
        };
        h.command = [this](const std::string &c) { return command(c); }; // the server's command thread
        h.api = [this](const std::string &name) { return api(name); };
        h.lastFrame = [this] {
            std::lock_guard<std::mutex> lock(lastMutex_);
            return lastMessage_;
        };
        // Block the stop signals in every thread made from here; this one waits for them.
        sigset_t signals;
        sigemptyset(&signals);
        sigaddset(&signals, SIGINT);
        sigaddset(&signals, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &signals, nullptr);

        checkExposure(options_);
        ServerOptions serving;
        serving.address = options_.address;
        serving.port = static_cast<uint16_t>(options_.port);
        serving.token = makeToken();
        serving.allowed_hosts = options_.allowed_hosts;
        server_ = std::make_unique<Server>(serving, h);
        if (listening) listening(server_->url());
        std::thread encoder([this] { encoderLoop(); });
        std::thread pipeline([this] { pipelineLoop(); });

        while (!finished_) {
            timespec wait{0, 100 * 1000 * 1000};
            const int sig = sigtimedwait(&signals, nullptr, &wait);
            if (sig == SIGINT || sig == SIGTERM) {
                spdlog::info("view: stopping (signal {})", sig == SIGINT ? "SIGINT" : "SIGTERM");
                break;
            }
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            quit_ = true;
            updateWanted();
        }
        cv_.notify_all();
        pipeline.join();
        {
            std::lock_guard<std::mutex> lock(slotMutex_);
            encoderQuit_ = true;
        }
        slotCv_.notify_all();
        encoder.join();
        server_->stop(); // no command runs past here
        server_.reset();
        pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);

        ViewSummary s;
        std::lock_guard<std::mutex> lock(mutex_);
        std::lock_guard<std::mutex> stats(statsMutex_);
        s.frames = processed_;
        s.frames_sent = sent_;
        s.encode_seconds = encodeSeconds_;
        s.seconds = std::chrono::duration<double>(lastFrameEnd_ - firstFrameStart_).count();
        s.pipeline_fps = s.seconds > 0 ? processed_ / s.seconds : 0;
        s.processing_fps = busySeconds_ > 0 ? processed_ / busySeconds_ : 0;
        s.status = status_;
        return s;
    }

private:
    // ---- Pipeline thread ------------------------------------------------------------
    void pipelineLoop() {
        for (;;) {
            RigConfig rig;
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (quit_) break;
                rig = rig_;
                running_ = true;
                restart_ = false;
                status_ = "running";
                error_.clear();
                updateWanted();
            }
            broadcastState();
            std::string failure;
            try {
                Pipeline pipeline(rig, host_);
                Watcher watcher(*this, pipeline);
                pipeline.addObserver(&watcher);
                RunOptions run;
                run.progress = false;
                run.max_frames = options_.max_frames > 0 ? options_.max_frames - processed_.load() : -1;
                // The stages run in parallel; they drain to one frame in flight only while
                // a change, a pause or a stop waits (wanted_).
                run.between_frames = [&] { return betweenFrames(pipeline); };
                run.between_frames_wanted = &wanted_;
                pipeline.run(run);
            } catch (const std::exception &e) {
                failure = e.what();
                spdlog::error("view: the pipeline stopped: {}", failure);
            }
            std::unique_lock<std::mutex> lock(mutex_);
            running_ = false;
            if (!quit_ && !restart_) {
                status_ = failure.empty() ? "ended" : "failed";
                error_ = failure;
                if (options_.max_frames > 0 && processed_ >= options_.max_frames) finished_ = true;
                lock.unlock();
                broadcastState();
                lock.lock();
                // Wait for a restart (the page's button, or a setting changed).
                cv_.wait(lock, [&] { return quit_ || restart_; });
            }
            if (quit_) {
                if (status_ == "running") status_ = "stopped";
                break;
            }
        }
        finished_ = true;
    }

    // Whether the acquire stage must stop at the next frame boundary (under mutex_).
    void updateWanted() {
        wanted_ = quit_ || restart_ || paused_ || step_ || pendingRig_.has_value();
        pausedNow_ = paused_;
    }

    // On the acquire stage, with no frame in flight (RunOptions::between_frames).
    bool betweenFrames(Pipeline &pipeline) {
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            if (quit_ || restart_) return false;
            if (pendingRig_) {
                RigConfig rig = std::move(*pendingRig_);
                std::vector<Override> overrides = pendingOverrides_;
                pendingRig_.reset();
                lock.unlock();
                std::string failure;
                try {
                    pipeline.reconfigure(rig);
                } catch (const std::exception &e) {
                    failure = e.what();
                }
                lock.lock();
                if (failure.empty()) {
                    rig_ = std::move(rig);
                    overrides_ = std::move(overrides);
                    lastChange_ = "applied";
                } else {
                    lastChange_ = "refused";
                    spdlog::warn("view: a plugin refused the change: {}", logExcerpt(failure));
                }
                lock.unlock();
                broadcastState();
                if (!failure.empty()) server_->broadcastText(dumpJson(errorReply("set", failure)));
                lock.lock();
                if (paused_) step_ = true; // show what the change does
                updateWanted();
                continue;
            }
            if (!paused_ || step_) {
                step_ = false;
                updateWanted();
                return true;
            }
            cv_.wait(lock);
        }
    }

    // The pipeline's observer, on its writer stage: counts every frame, and copies one
    // for the encoder only when a browser has taken the last one, the encoder is idle
    // and the display rate allows; every other frame costs a few comparisons.
    class Watcher : public FrameObserver {
    public:
        Watcher(View &view, Pipeline &pipeline) : view_(view), pipeline_(pipeline) {}
        void onFrame(const FrameResult &r) override { view_.onFrame(pipeline_, r); }

    private:
        View &view_;
        Pipeline &pipeline_;
    };

    void onFrame(Pipeline &pipeline, const FrameResult &r) {
        const auto now = Clock::now();
        double fps = 0;
        {
            std::lock_guard<std::mutex> lock(statsMutex_);
            if (processed_ == 0) firstFrameStart_ = now - std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(r.seconds));
            lastFrameEnd_ = now;
            busySeconds_ += r.seconds;
            recent_.push_back(now);
            while (recent_.size() > 2 && now - recent_.front() > std::chrono::seconds(2)) recent_.pop_front();
            const double span = std::chrono::duration<double>(recent_.back() - recent_.front()).count();
            fps = recent_.size() > 1 && span > 0 ? (recent_.size() - 1) / span : 0;
        }
        const int64_t processed = ++processed_;
        // While paused, the frames still in flight and a stepped one are what the user
        // waits for (now, or when a page opens): each replaces the one waiting, whatever
        // the browsers are doing.
        const bool paused = pausedNow_;
        if (!paused && (encoderBusy_ || now - lastHandOver_.load() < minInterval_ || !server_->wantsFrame())) return;
        auto p = std::make_shared<FrameProducts>(copyFrame(r));
        p->frames_processed = static_cast<uint64_t>(processed);
        p->pipeline_fps = fps;
        p->disparity_range = pipeline.matcherDisparityRange();
        p->focal_length_px = pipeline.calibration().focalLengthPx();
        p->baseline_mm = pipeline.calibration().baselineMm();
        p->source_statistics = pipeline.sourceStatistics(); // the source belongs to the acquire stage
        {
            std::lock_guard<std::mutex> slot(slotMutex_);
            slot_ = std::move(p);
            encoderBusy_ = true;
            lastHandOver_ = now;
        }
        slotCv_.notify_all();
    }

    // ---- Encoder thread -------------------------------------------------------------
    void encoderLoop() {
        std::unique_lock<std::mutex> lock(slotMutex_);
        for (;;) {
            slotCv_.wait(lock, [&] { return slot_ || encoderQuit_; });
            if (encoderQuit_) return;
            std::shared_ptr<const FrameProducts> p = std::move(slot_);
            slot_.reset();
            lock.unlock();
            std::shared_ptr<const std::string> message;
            const auto t0 = Clock::now();
            // The 3D view gets a new cloud at most cloud_fps times a second (drawing one
            // costs a browser more than the six images), and always while paused (a
            // stepped frame shows all of itself) or when a page has just opened.
            EncodeOptions encode = encode_;
            encode.with_cloud = pausedNow_ || cloudWanted_.exchange(false) || t0 - lastCloud_ >= cloudInterval_;
            if (encode.with_cloud) lastCloud_ = t0;
            try {
                message = std::make_shared<const std::string>(encodeFrame(*p, encode));
            } catch (const std::exception &e) {
                spdlog::error("view: frame {} could not be encoded: {}", p->result.sequence, e.what());
            }
            encodeSeconds_ += std::chrono::duration<double>(Clock::now() - t0).count(); // this thread only
            if (message) {
                {
                    std::lock_guard<std::mutex> last(lastMutex_);
                    last_ = p;
                    lastMessage_ = message;
                }
                server_->broadcastFrame(message);
                ++sent_;
            }
            lock.lock();
            encoderBusy_ = slot_ != nullptr; // a paused frame may have come meanwhile
        }
    }

    // ---- Server thread --------------------------------------------------------------
    OJson state(bool hello) {
        std::lock_guard<std::mutex> lock(mutex_);
        OJson s = {{"type", hello ? "hello" : "state"}};
        s["rig"] = {{"name", rig_.name}, {"file", rig_.file}};
        s["status"] = status_;
        s["error"] = error_;
        s["paused"] = paused_;
        s["running"] = running_;
        s["last_change"] = lastChange_;
        s["frames_processed"] = processed_.load();
        const std::vector<Override> &shown = pendingRig_ ? pendingOverrides_ : overrides_;
        OJson list = OJson::array();
        for (const Override &o : shown) list.push_back({{"key", o.path}, {"value", o.value}});
        s["overrides"] = list;
        s["set_lines"] = setLines(shown);
        s["blocks"] = settingsSchema(pendingRig_ ? *pendingRig_ : rig_);
        s["snapshot_dir"] = fs::absolute(options_.out_dir).lexically_normal().string();
        if (hello) s["color_scale"] = colorScale();
        return s;
    }
    void broadcastState() {
        if (server_) server_->broadcastState(dumpJson(state(false)));
    }

    static std::string setLines(const std::vector<Override> &overrides) {
        std::string out;
        for (const Override &o : overrides) out += "--set " + o.path + "=" + o.value + "\n";
        return out;
    }

    std::string command(const std::string &text) {
        Command c;
        try {
            c = parseCommand(text);
        } catch (const CommandError &e) {
            OJson r = errorReply(e.op, e.what());
            if (!e.key.empty()) r["key"] = e.key;
            return dumpJson(r);
        }
        OJson reply = {{"type", "ok"}, {"op", c.name}};
        switch (c.op) {
        case Op::Set: return dumpJson(set(c.key, c.value));
        case Op::Reset: return dumpJson(applyOverrides(options_.overrides, "reset"));
        case Op::Snapshot: return dumpJson(snapshot());
        case Op::Pause:
        case Op::Resume: {
            std::lock_guard<std::mutex> lock(mutex_);
            paused_ = c.op == Op::Pause;
            updateWanted();
            break;
        }
        case Op::Step: {
            std::lock_guard<std::mutex> lock(mutex_);
            paused_ = true;
            step_ = true;
            updateWanted();
            break;
        }
        case Op::Restart: {
            std::lock_guard<std::mutex> lock(mutex_);
            restart_ = true;
            updateWanted();
            break;
        }
        }
        cv_.notify_all();
        broadcastState();
        return dumpJson(reply);
    }

    // A change from the page: a declared, non-limit plugin setting (page_), checked by the
    // host's validation exactly as --set is, with its paths kept inside the rig's folders.
    OJson set(const std::string &key, const std::string &value) {
        auto refused = [&](const std::string &why) {
            OJson r = errorReply("set", why);
            r["key"] = key;
            return r;
        };
        if (const std::string why = page_->refuseKey(key); !why.empty()) return refused(why);
        std::vector<Override> candidate;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            candidate = pendingRig_ ? pendingOverrides_ : overrides_;
        }
        Override o;
        try {
            o = Override::parse(key + "=" + value);
        } catch (const Error &e) {
            return refused(e.what());
        }
        auto same = std::find_if(candidate.begin(), candidate.end(), [&](const Override &x) { return x.path == o.path; });
        if (same != candidate.end()) candidate.erase(same);
        candidate.push_back(o);
        size_t bytes = 0;
        for (const Override &x : candidate) bytes += x.path.size() + x.value.size();
        if (bytes > kMaxPageSettingsBytes)
            return refused("view: the settings changed from the page would hold " + std::to_string(bytes) + " bytes; expected at most " +
                           std::to_string(kMaxPageSettingsBytes) + " (reset, or put large values in the rig file)");
        OJson r = applyOverrides(candidate, "set", true);
        r["key"] = key;
        return r;
    }

    OJson applyOverrides(const std::vector<Override> &overrides, const std::string &op, bool fromPage = false) {
        RigConfig rig;
        try {
            rig = loadRig(options_.rig_file, overrides, host_);
        } catch (const std::exception &e) {
            return errorReply(op, e.what());
        }
        if (fromPage)
            if (const std::string why = page_->refusePaths(rig); !why.empty()) return errorReply(op, why);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            lastChange_ = "pending";
            if (running_) {
                pendingRig_ = std::move(rig);
                pendingOverrides_ = overrides;
            } else {
                // Nothing runs (the source ended or failed): start again with it.
                rig_ = std::move(rig);
                overrides_ = overrides;
                restart_ = true;
            }
            updateWanted();
        }
        cv_.notify_all();
        broadcastState();
        return {{"type", "accepted"}, {"op", op}};
    }

    OJson snapshot() {
        std::shared_ptr<const FrameProducts> p;
        {
            std::lock_guard<std::mutex> lock(lastMutex_);
            p = last_;
        }
        if (!p) return errorReply("snapshot", "view: no frame has been shown yet");
        OutputOptions outputs;
        std::string yaml;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            outputs = rig_.outputs;
            yaml = rig_.resolved_yaml;
        }
        try {
            const std::vector<std::string> files = writeSnapshot(*p, outputs, yaml, encode_.grid, options_.out_dir);
            spdlog::info("view: frame {} written to {} ({} files)", p->result.sequence, options_.out_dir, files.size());
            return {{"type", "snapshot"}, {"sequence", p->result.sequence}, {"dir", fs::absolute(options_.out_dir).string()}, {"files", files}};
        } catch (const std::exception &e) {
            return errorReply("snapshot", e.what());
        }
    }

    HttpReply api(const std::string &name) {
        if (name == "state") return {200, "application/json", dumpJson(state(false)), ""};
        if (name == "rig.yaml") {
            std::lock_guard<std::mutex> lock(mutex_);
            // Values are escaped in the comments: a line break in one must not end the comment.
            std::string text = "# Saved by binocle view from " + sdk::printable(rig_.file, 400) + "\n# with:\n";
            for (const Override &o : overrides_) text += "#   --set " + sdk::printable(o.path + "=" + o.value, 200) + "\n";
            text += "# Relative paths are relative to " + rig_.base_dir + ": save this file there.\n";
            text += rig_.resolved_yaml + "\n";
            return {200, "application/yaml; charset=utf-8", text, rig_.name + "-view.yaml"};
        }
        if (name == "set-lines.txt") {
            std::lock_guard<std::mutex> lock(mutex_);
            return {200, "text/plain; charset=utf-8", setLines(overrides_), ""};
        }
        return {404, "text/plain", "", ""};
    }

    const ViewOptions options_;
    const PluginHost &host_;
    EncodeOptions encode_;
    Clock::duration minInterval_{0}, cloudInterval_{0};
    Clock::time_point lastCloud_{}; // encoder thread
    std::atomic<bool> cloudWanted_{false};

    // Guarded by mutex_.
    std::mutex mutex_;
    std::condition_variable cv_;
    RigConfig rig_;
    std::vector<Override> overrides_ = options_.overrides;
    std::optional<RigConfig> pendingRig_;
    std::vector<Override> pendingOverrides_;
    bool paused_ = false, step_ = false, quit_ = false, restart_ = false, running_ = false;
    std::string status_ = "starting", error_, lastChange_;
    std::atomic<bool> finished_{false};
    // What the pipeline's stages read without taking mutex_ (updateWanted()).
    std::atomic<bool> wanted_{false}, pausedNow_{false};

    // Counted by the observer (writer stage); statsMutex_ guards the times.
    std::atomic<int64_t> processed_{0}, sent_{0};
    std::mutex statsMutex_;
    double busySeconds_ = 0;
    Clock::time_point firstFrameStart_{}, lastFrameEnd_{};
    std::deque<Clock::time_point> recent_;

    // The hand-over slot (observer -> encoder); encoderBusy_ and lastHandOver_ are
    // written under slotMutex_ and read by the observer without it.
    std::mutex slotMutex_;
    std::condition_variable slotCv_;
    std::shared_ptr<FrameProducts> slot_;
    bool encoderQuit_ = false;
    double encodeSeconds_ = 0; // encoder thread; read after it is joined
    std::atomic<bool> encoderBusy_{false};
    std::atomic<Clock::time_point> lastHandOver_{};

    // The frame on screen.
    std::mutex lastMutex_;
    std::shared_ptr<const FrameProducts> last_;
    std::shared_ptr<const std::string> lastMessage_;

    std::unique_ptr<PageSettings> page_; // what the page may change, from the rig as started
    std::unique_ptr<Server> server_;
};

} // namespace

ViewSummary runView(const ViewOptions &options, const PluginHost &host, const std::function<void(const std::string &)> &listening) {
    View view(options, host);
    return view.run(listening);
}

} // namespace binocle::viewer
