// SPDX-License-Identifier: MIT
// The live view: a pipeline thread, an encoder thread and the server thread. The
// pipeline hands a frame over only when a browser is ready for one and the encoder is
// idle (a try-lock, never a wait); settings are validated like --set and applied by the
// pipeline itself between frames.
#include "viewer/viewer.hpp"

#include "core/error.hpp"
#include "pipeline/pipeline.hpp"
#include "viewer/frame_snapshot.hpp"
#include "viewer/server.hpp"
#include "viewer/settings_schema.hpp"

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

namespace fs = std::filesystem;

namespace binocle::viewer {

namespace {

using OJson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

std::string dumpJson(const OJson &j) { return j.dump(-1, ' ', false, OJson::error_handler_t::replace); }

class View {
public:
    View(const ViewOptions &options, const PluginHost &host) : options_(options), host_(host) {
        rig_ = loadRig(options.rig_file, options.overrides, host);
        paused_ = options.paused;
        step_ = options.paused; // paused from the start: one frame to look at
        if (options.display_fps > 0)
            minInterval_ = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.display_fps));
        encode_.grid = method::GridSpec{};
    }

    ViewSummary run(const std::function<void(const std::string &)> &listening) {
        ServerHandlers h;
        h.hello = [this] { return dumpJson(state(true)); };
        h.command = [this](const std::string &c) { return command(c); };
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

        server_ = std::make_unique<Server>(options_.address, static_cast<uint16_t>(options_.port), makeToken(), h);
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
        }
        cv_.notify_all();
        pipeline.join();
        {
            std::lock_guard<std::mutex> lock(slotMutex_);
            encoderQuit_ = true;
        }
        slotCv_.notify_all();
        encoder.join();
        server_.reset();
        pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);

        ViewSummary s;
        std::lock_guard<std::mutex> lock(mutex_);
        s.frames = processed_;
        s.frames_sent = sent_;
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
            }
            broadcastState();
            std::string failure;
            try {
                Pipeline pipeline(rig, host_);
                RunOptions run;
                run.progress = false;
                run.max_frames = options_.max_frames > 0 ? options_.max_frames - processed_ : -1;
                run.between_frames = [&] { return betweenFrames(pipeline); };
                pipeline.run(run, [&](const FrameResult &r) { onFrame(pipeline, r); });
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
                    spdlog::warn("view: a plugin refused the change: {}", failure);
                }
                lock.unlock();
                broadcastState();
                if (!failure.empty()) server_->broadcastText(dumpJson({{"type", "error"}, {"message", failure}}));
                lock.lock();
                if (paused_) step_ = true; // show what the change does
                continue;
            }
            if (!paused_ || step_) {
                step_ = false;
                return true;
            }
            cv_.wait(lock);
        }
    }

    void onFrame(Pipeline &pipeline, const FrameResult &r) {
        const auto now = Clock::now();
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (processed_ == 0) firstFrameStart_ = now - std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(r.seconds));
            lastFrameEnd_ = now;
            ++processed_;
            busySeconds_ += r.seconds;
            recent_.push_back(now);
            while (recent_.size() > 2 && now - recent_.front() > std::chrono::seconds(2)) recent_.pop_front();
        }
        bool stepped = false;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stepped = paused_;
        }
        std::unique_lock<std::mutex> slot(slotMutex_, std::defer_lock);
        if (stepped) {
            // A frame made by `step`: the user waits for exactly this one, and the
            // pipeline is paused anyway, so it waits for the encoder rather than skip.
            if (server_->browsers() == 0) return;
            slot.lock();
            slotCv_.wait(slot, [&] { return (!slot_ && !encoderBusy_) || encoderQuit_; });
        } else {
            // The display takes a frame only when someone can look at it; otherwise this
            // callback costs a few comparisons.
            if (!server_->wantsFrame() || encoderBusy_ || now - lastHandOver_ < minInterval_) return;
            slot.try_lock();
            if (!slot.owns_lock() || slot_) return;
        }
        auto p = std::make_shared<FrameProducts>(copyFrame(r));
        {
            std::lock_guard<std::mutex> lock(mutex_);
            p->frames_processed = static_cast<uint64_t>(processed_);
            const double span = std::chrono::duration<double>(recent_.back() - recent_.front()).count();
            p->pipeline_fps = recent_.size() > 1 && span > 0 ? (recent_.size() - 1) / span : 0;
        }
        p->disparity_range = pipeline.matcherDisparityRange();
        p->focal_length_px = pipeline.calibration().focalLengthPx();
        p->baseline_mm = pipeline.calibration().baselineMm();
        p->source_statistics = pipeline.sourceStatistics(); // the source belongs to the acquire stage
        slot_ = std::move(p);
        encoderBusy_ = true;
        lastHandOver_ = now;
        slot.unlock();
        slotCv_.notify_all();
    }

    // ---- Encoder thread -------------------------------------------------------------
    void encoderLoop() {
        std::unique_lock<std::mutex> lock(slotMutex_);
        for (;;) {
            slotCv_.wait(lock, [&] { return slot_ || encoderQuit_; });
            // (the pipeline's hand-over waits on the same condition variable)
            if (encoderQuit_) return;
            std::shared_ptr<const FrameProducts> p = std::move(slot_);
            slot_.reset();
            lock.unlock();
            std::shared_ptr<const std::string> message;
            try {
                message = std::make_shared<const std::string>(encodeFrame(*p, encode_));
            } catch (const std::exception &e) {
                spdlog::error("view: frame {} could not be encoded: {}", p->result.sequence, e.what());
            }
            if (message) {
                {
                    std::lock_guard<std::mutex> last(lastMutex_);
                    last_ = p;
                    lastMessage_ = message;
                }
                server_->broadcastFrame(message);
                std::lock_guard<std::mutex> counters(mutex_);
                ++sent_;
            }
            lock.lock();
            encoderBusy_ = false;
            slotCv_.notify_all(); // a stepped frame may be waiting for the encoder
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
        s["frames_processed"] = processed_;
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
        if (server_) server_->broadcastText(dumpJson(state(false)));
    }

    static std::string setLines(const std::vector<Override> &overrides) {
        std::string out;
        for (const Override &o : overrides) out += "--set " + o.path + "=" + o.value + "\n";
        return out;
    }

    std::string command(const std::string &text) {
        const OJson c = OJson::parse(text, nullptr, false);
        if (c.is_discarded() || !c.is_object() || !c.contains("op") || !c["op"].is_string())
            return dumpJson({{"type", "error"}, {"message", "view: a command is a JSON object with \"op\""}});
        const std::string op = c["op"];
        OJson reply = {{"type", "ok"}, {"op", op}};
        if (op == "set") {
            if (!c.contains("key") || !c["key"].is_string() || !c.contains("value") || !c["value"].is_string())
                return dumpJson({{"type", "error"}, {"op", op}, {"message", "view: set needs \"key\" and \"value\" (YAML text)"}});
            return dumpJson(set(c["key"], c["value"]));
        } else if (op == "pause" || op == "resume") {
            std::lock_guard<std::mutex> lock(mutex_);
            paused_ = op == "pause";
        } else if (op == "step") {
            std::lock_guard<std::mutex> lock(mutex_);
            paused_ = true;
            step_ = true;
        } else if (op == "restart") {
            std::lock_guard<std::mutex> lock(mutex_);
            restart_ = true;
        } else if (op == "reset") {
            return dumpJson(applyOverrides(options_.overrides, "reset"));
        } else if (op == "snapshot") {
            return dumpJson(snapshot());
        } else {
            return dumpJson({{"type", "error"},
                             {"op", op},
                             {"message", "view: unknown command '" + op + "' (set, pause, resume, step, restart, reset, snapshot)"}});
        }
        cv_.notify_all();
        broadcastState();
        return dumpJson(reply);
    }

    // A change from the page goes through the host's validation exactly as --set does.
    OJson set(const std::string &key, const std::string &value) {
        std::vector<Override> candidate;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            candidate = pendingRig_ ? pendingOverrides_ : overrides_;
        }
        Override o;
        try {
            o = Override::parse(key + "=" + value);
        } catch (const Error &e) {
            return {{"type", "error"}, {"op", "set"}, {"key", key}, {"message", e.what()}};
        }
        auto same = std::find_if(candidate.begin(), candidate.end(), [&](const Override &x) { return x.path == o.path; });
        if (same != candidate.end()) candidate.erase(same);
        candidate.push_back(o);
        OJson r = applyOverrides(candidate, "set");
        r["key"] = key;
        return r;
    }

    OJson applyOverrides(const std::vector<Override> &overrides, const std::string &op) {
        RigConfig rig;
        try {
            rig = loadRig(options_.rig_file, overrides, host_);
        } catch (const std::exception &e) {
            return {{"type", "error"}, {"op", op}, {"message", e.what()}};
        }
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
        if (!p) return {{"type", "error"}, {"op", "snapshot"}, {"message", "view: no frame has been shown yet"}};
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
            return {{"type", "error"}, {"op", "snapshot"}, {"message", e.what()}};
        }
    }

    HttpReply api(const std::string &name) {
        if (name == "state") return {200, "application/json", dumpJson(state(false)), ""};
        if (name == "rig.yaml") {
            std::lock_guard<std::mutex> lock(mutex_);
            std::string text = "# Saved by binocle view from " + rig_.file + "\n# with:\n";
            for (const Override &o : overrides_) text += "#   --set " + o.path + "=" + o.value + "\n";
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
    Clock::duration minInterval_{0};

    // Guarded by mutex_.
    std::mutex mutex_;
    std::condition_variable cv_;
    RigConfig rig_;
    std::vector<Override> overrides_ = options_.overrides;
    std::optional<RigConfig> pendingRig_;
    std::vector<Override> pendingOverrides_;
    bool paused_ = false, step_ = false, quit_ = false, restart_ = false, running_ = false;
    std::string status_ = "starting", error_, lastChange_;
    int64_t processed_ = 0, sent_ = 0;
    double busySeconds_ = 0;
    Clock::time_point firstFrameStart_{}, lastFrameEnd_{};
    std::deque<Clock::time_point> recent_;
    std::atomic<bool> finished_{false};

    // The hand-over slot (pipeline -> encoder).
    std::mutex slotMutex_;
    std::condition_variable slotCv_;
    std::shared_ptr<FrameProducts> slot_;
    bool encoderQuit_ = false;
    std::atomic<bool> encoderBusy_{false};
    Clock::time_point lastHandOver_{};

    // The frame on screen.
    std::mutex lastMutex_;
    std::shared_ptr<const FrameProducts> last_;
    std::shared_ptr<const std::string> lastMessage_;

    std::unique_ptr<Server> server_;
};

} // namespace

ViewSummary runView(const ViewOptions &options, const PluginHost &host, const std::function<void(const std::string &)> &listening) {
    View view(options, host);
    return view.run(listening);
}

} // namespace binocle::viewer
