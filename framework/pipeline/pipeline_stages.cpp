// SPDX-License-Identifier: MIT
// What each stage thread of a run does: acquire | rectify + match | cloud + transforms |
// evaluators | writer. The run's shared state is in pipeline_run.hpp; pipeline.cpp starts
// the threads and writes the summary.
#include "pipeline/pipeline_run.hpp"

#include "core/error.hpp"
#include "core/image_io.hpp"
#include "core/json.hpp"
#include "core/progress.hpp"
#include "pipeline/source_grab.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>
#include <thread>

namespace binocle {

namespace {

// The pose of Eq. 1 for the evaluators: the settings camera_height_mm and
// inclination_deg of the first transform that declares both (cloud_transform.h).
void putGroundPose(binocle_eval_input &in, const RigConfig &rig) {
    auto number = [](const binocle_param *p) {
        return p->type == BINOCLE_PARAM_INT ? static_cast<double>(p->i) : p->d;
    };
    for (const auto &t : rig.transforms()) {
        const binocle_param *h = t.params.find("camera_height_mm"), *i = t.params.find("inclination_deg");
        if (!h || !i) continue;
        in.ground_pose_known = 1;
        in.camera_height_mm = number(h);
        in.inclination_deg = number(i);
        return;
    }
}

} // namespace

// Stage 1: grabs pairs and queues them by the policy. A grab waits in short slices so
// that a stop request is seen within a fraction of a second even from a silent camera
// (grabWithin, shared with the recorder).
void Pipeline::acquire(RunState &s) {
    const RuntimeOptions &rt = rig_.runtime;
    const bool retry = rt.on_source_error == RuntimeOptions::OnSourceError::Retry;
    // When the source's outage began (retry mode); none: the source is delivering. A
    // time point and a flag, not std::optional: GCC 12 warns (wrongly) that the optional's
    // value may be read uninitialized.
    Clock::time_point outageSince{};
    bool inOutage = false;
    auto pause = [&](std::chrono::milliseconds d) {
        const auto until = Clock::now() + d;
        while (Clock::now() < until && !s.stopRequested() && !s.aborted)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    };
    try {
        source().start();
        sourceStarted_ = true;
        refreshSourceStatistics();
        auto lastStatistics = Clock::now();
        while (!s.stopRequested() && !s.aborted) {
            if (s.options.max_frames >= 0 && s.grabbed >= s.options.max_frames) break;
            if (s.options.between_frames && (!s.options.between_frames_wanted || s.options.between_frames_wanted->load())) {
                // Drain: every grabbed frame through the writer, so that no stage runs a
                // plugin or holds a frame while the hook may reconfigure the pipeline.
                std::unique_lock<std::mutex> lock(s.doneMutex);
                while (s.finished + s.droppedByPolicy < s.grabbed && !s.aborted && !s.stopRequested())
                    s.doneCv.wait_for(lock, std::chrono::milliseconds(100));
                lock.unlock();
                if (s.aborted || s.stopRequested() || !s.options.between_frames()) break;
            }
            std::unique_ptr<LentFrame> frame;
            const auto grabStart = Clock::now();
            try {
                frame = grabWithin(source(), s.options.grab_timeout_ms, [&] { return s.stopRequested() || s.aborted; });
            } catch (const PluginError &e) {
                if (s.stopRequested() && e.code() == BINOCLE_ERR_TIMEOUT) break;
                if (!retry || (e.code() != BINOCLE_ERR_DEVICE && e.code() != BINOCLE_ERR_TIMEOUT)) throw;
                if (!inOutage) {
                    inOutage = true;
                    outageSince = Clock::now();
                    ++s.sourceErrors;
                    s.lastSourceError = e.what();
                    spdlog::warn("source error, retrying for up to {} s: {}", rt.retry_for_s, e.what());
                }
                if (secondsSince(outageSince) > rt.retry_for_s)
                    throw Error(std::string(e.what()) + " (still failing after retry_for_s: " + std::to_string(rt.retry_for_s) + " s)");
                pause(std::chrono::milliseconds(100));
                continue;
            }
            if (inOutage) {
                ++s.recoveries;
                spdlog::info("source recovered after {:.1f} s", secondsSince(outageSince));
                inOutage = false;
            }
            if (!frame) {
                s.endOfStream = true;
                break;
            }
            const double grabSeconds = secondsSince(grabStart);
            if (!calibrationReady_) {
                checkQueueMemory(*frame);
                prepareCalibration(frame->left().size());
            }
            checkFrameSize(*frame, s.grabbed);
            if (Clock::now() - lastStatistics > std::chrono::milliseconds(500)) {
                refreshSourceStatistics();
                lastStatistics = Clock::now();
            }
            ++s.grabbed;
            RunState::Grabbed g{std::move(frame), Clock::now(), grabSeconds};
            if (s.policy == RuntimeOptions::Policy::Latest) {
                if (s.sourceQueue.pushDropOldest(std::move(g))) ++s.droppedByPolicy; // released here
            } else if (!s.sourceQueue.pushWait(g)) {
                break;
            }
        }
    } catch (const std::exception &e) {
        s.fail(e.what(), false);
    }
    s.sourceQueue.close();
}

// Stage 2 (one thread per matcher instance): rectify into pooled images, then match.
void Pipeline::rectifyAndMatch(RunState &s, size_t instance) {
    for (;;) {
        std::unique_ptr<Job> job = s.takeJob();
        uint64_t ordinal = 0;
        std::optional<RunState::Grabbed> g = s.sourceQueue.pop(ordinal);
        if (!g) {
            s.giveJob(std::move(job));
            break;
        }
        FrameResult &r = job->r;
        job->frame = std::move(g->frame);
        job->grabbed = g->at;
        job->failed = s.aborted;
        r.index = ordinal;
        r.sequence = job->frame->raw().sequence;
        r.frame = job->frame.get();
        r.seconds = 0;
        r.acquire_seconds = g->seconds;
        r.stage_seconds.clear();
        if (!job->failed) {
            try {
                // Read per frame: reconfigure() may have replaced it between frames.
                Matcher &matcher = *instances_->of<Matcher>()[instance];
                const auto t0 = Clock::now();
                const cv::Mat left = job->frame->left(), right = job->frame->right();
                if (calibration_.rectified) {
                    r.rectified_left = left; // zero-copy: the frame stays lent until the writer is done
                    r.rectified_right = right;
                } else {
                    cv::remap(left, r.rectified_left, map1x_, map1y_, cv::INTER_LINEAR);
                    cv::remap(right, r.rectified_right, map2x_, map2y_, cv::INTER_LINEAR);
                }
                r.stage_seconds.emplace_back("rectify", secondsSince(t0));
                const auto t1 = Clock::now();
                matcher.compute(r.rectified_left, r.rectified_right, r.disparity);
                r.disparity_extras = matcher.extras(); // new buffers each compute: a shallow copy
                r.stage_seconds.emplace_back("match", secondsSince(t1));
                r.seconds += secondsSince(t0);
            } catch (const std::exception &e) {
                s.fail(e.what());
                job->failed = true;
            }
        }
        s.matched.push(ordinal, std::move(job));
    }
    s.matched.producerDone();
}

// Stage 3: cloud in camera coordinates (pooled arrays), then the transforms.
void Pipeline::cloudAndTransforms(RunState &s) {
    while (std::optional<std::unique_ptr<Job>> job = s.matched.pop()) {
        FrameResult &r = (*job)->r;
        if (!(*job)->failed && !s.aborted) {
            try {
                const auto t0 = Clock::now();
                const size_t valid = projector_.project(r.disparity, r.rectified_left, r.cloud);
                r.valid_pixel_ratio = static_cast<double>(valid) / static_cast<double>(r.disparity.total());
                r.stage_seconds.emplace_back("cloud", secondsSince(t0));
                const auto t1 = Clock::now();
                for (const auto &t : instances_->of<CloudTransform>()) {
                    binocle_cloud view = r.cloud.view();
                    t->apply(view);
                    r.cloud.adopt(view);
                }
                r.stage_seconds.emplace_back("transforms", secondsSince(t1));
                r.seconds += secondsSince(t0);
            } catch (const std::exception &e) {
                s.fail(e.what());
                (*job)->failed = true;
            }
        } else {
            (*job)->failed = true;
        }
        const uint64_t index = r.index;
        s.clouded.push(index, std::move(*job));
    }
    s.clouded.producerDone();
}

// Stage 4: the evaluators, in order, on one thread.
void Pipeline::evaluate(RunState &s) {
    while (std::optional<std::unique_ptr<Job>> job = s.clouded.pop()) {
        FrameResult &r = (*job)->r;
        r.metrics = Json::object();
        r.figures.clear();
        const auto &evaluators = instances_->of<EvaluatorSlot>();
        if (!(*job)->failed && !s.aborted && evaluators.empty()) r.stage_seconds.emplace_back("evaluators", 0.0);
        if (!(*job)->failed && !s.aborted && !evaluators.empty()) {
            try {
                const auto t0 = Clock::now();
                binocle_image rl{}, rr{}, d{};
                auto wrap = [](const cv::Mat &m, binocle_image &im) {
                    im.width = m.cols;
                    im.height = m.rows;
                    im.stride_bytes = static_cast<int32_t>(m.step[0]);
                    im.format = m.type() == CV_32F   ? BINOCLE_PIXEL_FLOAT32
                                : m.type() == CV_16U ? BINOCLE_PIXEL_GRAY16
                                : m.channels() == 3  ? BINOCLE_PIXEL_BGR8
                                                     : BINOCLE_PIXEL_GRAY8;
                    im.data = m.data;
                };
                wrap(r.rectified_left, rl);
                wrap(r.rectified_right, rr);
                wrap(r.disparity, d);
                binocle_cloud cloud = r.cloud.view();
                binocle_eval_input in{};
                in.struct_size = sizeof(in);
                in.frame = &(*job)->frame->raw();
                in.rectified_left = &rl;
                in.rectified_right = &rr;
                in.disparity = &d;
                in.cloud = &cloud;
                in.calibration_yaml = calibrationYaml_.c_str();
                in.rig_yaml = rig_.resolved_yaml.c_str();
                in.output_dir = outDir_.empty() ? nullptr : outDir_.c_str();
                in.min_disparity = disparityRange_.first;
                in.num_disparities = disparityRange_.second;
                putGroundPose(in, rig_);
                std::vector<binocle_named_image> extras;
                for (const NamedPlane &p : r.disparity_extras) {
                    binocle_image im{};
                    wrap(p.image, im);
                    extras.push_back({p.name.c_str(), im});
                }
                in.disparity_extras = extras.empty() ? nullptr : extras.data();
                in.disparity_extra_count = static_cast<int32_t>(extras.size());
                for (const auto &slot : evaluators) {
                    Json figures = Json::object();
                    slot->target = &figures;
                    slot->flat = &r.figures;
                    try {
                        slot->evaluator->evaluate(in);
                    } catch (...) {
                        slot->target = nullptr;
                        slot->flat = nullptr;
                        throw;
                    }
                    slot->target = nullptr;
                    slot->flat = nullptr;
                    r.metrics[slot->name] = std::move(figures);
                }
                r.stage_seconds.emplace_back("evaluators", secondsSince(t0));
                r.seconds += secondsSince(t0);
            } catch (const std::exception &e) {
                s.fail(e.what());
                (*job)->failed = true;
            }
        }
        const uint64_t index = r.index;
        s.evaluated.push(index, std::move(*job));
    }
    s.evaluated.producerDone();
}

// Stage 5, on the calling thread: the writers, the caller's onFrame, the observers; then
// the job goes back to the pool and the drain of between_frames learns of it.
void Pipeline::write(RunState &s, const std::function<void(const FrameResult &)> &onFrame) {
    Progress progress(s.options.progress, "frame", s.options.max_frames);
    while (std::optional<std::unique_ptr<Job>> job = s.evaluated.pop()) {
        FrameResult &r = (*job)->r;
        if (!(*job)->failed && !s.aborted) {
            try {
                const auto t0 = Clock::now();
                r.latency_s = secondsSince((*job)->grabbed);
                r.calibration = &calibration_;
                for (FrameWriter *w : s.writers) w->write(r);
                const double written = secondsSince(t0);
                r.seconds += written;
                if (onFrame) onFrame(r);
                for (FrameObserver *o : observers_) o->onFrame(r);
                s.times.add("acquire", r.acquire_seconds);
                for (const auto &[stage, seconds] : r.stage_seconds) s.times.add(stage, seconds);
                s.times.add("write", written);
                ++s.written;
                progress.update(s.written);
            } catch (const std::exception &e) {
                s.fail(e.what());
            }
        }
        // Views into the lent frame must not outlive it; owned buffers stay for reuse.
        if (calibration_.rectified) {
            r.rectified_left.release();
            r.rectified_right.release();
        }
        r.frame = nullptr;
        (*job)->frame.reset();
        s.giveJob(std::move(*job));
        {
            std::lock_guard<std::mutex> lock(s.doneMutex);
            ++s.finished;
        }
        s.doneCv.notify_all();
    }
}

} // namespace binocle
