// SPDX-License-Identifier: MIT
// Recording a rig's source to a folder in the recording format (sdk/include/binocle/recording.hpp):
// the layout, frames.csv and the durability rules are the SDK's; this adds the writer pool,
// and the loop that records a rig's source into any RecordingSink.
#include "pipeline/recorder.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"
#include "core/output_folder.hpp"
#include "core/progress.hpp"
#include "host/instance_support.hpp"
#include "pipeline/source_grab.hpp"

#include <binocle/recording.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fcntl.h>
#include <filesystem>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>
#include <thread>
#include <unistd.h>
#include <vector>
#include <yaml-cpp/yaml.h>

namespace fs = std::filesystem;

namespace binocle {

cv::Mat recordableView(const binocle_image &im) {
    switch (im.format) {
    case BINOCLE_PIXEL_GRAY8:
    case BINOCLE_PIXEL_GRAY16:
    case BINOCLE_PIXEL_BGR8:
    case BINOCLE_PIXEL_RGB8: return view(im);
    default:
        throw Error("record: images of format " + std::to_string(im.format) +
                    " cannot be recorded (GRAY8, GRAY16, BGR8 or RGB8)");
    }
}

namespace {

// Where a write failed, for the message: the filesystem holding `dir`, where it is
// mounted and how much room it has left. A full disk is the usual cause and the user
// must see which one.
std::string diskOf(const std::string &dir) {
    std::error_code ec;
    fs::path at = fs::absolute(dir, ec).lexically_normal();
    struct stat st {};
    if (::stat(at.c_str(), &st) != 0) return "";
    const dev_t device = st.st_dev;
    while (at.has_parent_path() && at.parent_path() != at) {
        struct stat up {};
        if (::stat(at.parent_path().c_str(), &up) != 0 || up.st_dev != device) break;
        at = at.parent_path();
    }
    struct statvfs vfs {};
    if (::statvfs(dir.c_str(), &vfs) != 0) return "";
    auto kib = [](unsigned long long bytes) { return std::to_string(bytes / 1024) + " KiB"; };
    std::string note = "the disk holding " + dir + " (the filesystem mounted at " + at.string() + ") has " +
                       kib(static_cast<unsigned long long>(vfs.f_bavail) * vfs.f_frsize) + " free of " +
                       kib(static_cast<unsigned long long>(vfs.f_blocks) * vfs.f_frsize);
    struct rlimit limit {};
    if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
        note += "; this process may write files of at most " + kib(static_cast<unsigned long long>(limit.rlim_cur)) +
                " (ulimit -f)";
    return note;
}


} // namespace

// The writer's threads: `threads` workers encode and write images, one committer appends
// rows in submission order once their images are durable.
struct RecordingWriter::Pool {
    struct Job {
        uint64_t sequence = 0;
        int64_t tl = 0, tr = 0;
        cv::Mat images[2];
        bool rgb = false;
        bool done = false;
        std::string error;
    };

    std::string dir, csvPath;
    RecordingWriterOptions options;
    int csvFd = -1, dirFds[2] = {-1, -1};

    mutable std::mutex mutex;
    std::condition_variable workAvailable, jobDone, roomAvailable, committed;
    std::deque<std::shared_ptr<Job>> todo;    // waiting for a worker
    std::deque<std::shared_ptr<Job>> inOrder; // submitted, row not yet durable
    int64_t inMemory = 0;                     // frames whose images are held (todo + being written)
    int64_t rows = 0, submitted = 0;
    bool stopping = false;          // workers: finish the queue and end
    bool committerStopping = false; // committer: list what is done and end (workers are gone)
    bool flushRequested = false;
    std::string error; // first failure; nothing after it is listed
    RecordingWriterStats stats;
    std::vector<std::thread> workers;
    std::thread committer;

    ~Pool() {
        for (int fd : {csvFd, dirFds[0], dirFds[1]})
            if (fd >= 0) ::close(fd);
    }

    void work() {
        std::unique_lock<std::mutex> lock(mutex);
        for (;;) {
            workAvailable.wait(lock, [&] { return stopping || !todo.empty(); });
            if (todo.empty()) return;
            std::shared_ptr<Job> job = todo.front();
            todo.pop_front();
            const bool skip = !error.empty(); // nothing after a failure is listed: not written either
            lock.unlock();
            double encodeMs = 0, writeMs = 0;
            try {
                if (!skip) writeImages(*job, encodeMs, writeMs);
            } catch (const std::exception &e) {
                job->error = e.what();
            }
            job->images[0].release();
            job->images[1].release();
            lock.lock();
            job->done = true;
            --inMemory;
            stats.encode_ms += encodeMs;
            stats.write_ms += writeMs;
            const bool orphan = !error.empty(); // the committer has given up on it
            roomAvailable.notify_all();
            jobDone.notify_all();
            if (orphan && !skip) {
                lock.unlock();
                removeImages({job});
                lock.lock();
            }
        }
    }

    void writeImages(Job &job, double &encodeMs, double &writeMs) const {
        for (int i = 0; i < 2; ++i) {
            const std::string file = (fs::path(dir) / recording::imagePath(i, job.sequence)).string();
            const auto t0 = std::chrono::steady_clock::now();
            cv::Mat toWrite = job.images[i];
            if (job.rgb && toWrite.channels() == 3) cv::cvtColor(toWrite, toWrite, cv::COLOR_RGB2BGR);
            std::vector<uchar> png;
            try {
                if (!cv::imencode(".png", toWrite, png, {cv::IMWRITE_PNG_COMPRESSION, options.png_compression}))
                    throw Error("record: cannot encode " + file);
            } catch (const cv::Exception &e) {
                throw Error("record: cannot encode " + file + ": " + e.err);
            }
            const auto t1 = std::chrono::steady_clock::now();
            // Temporary file, fsync, rename: the image is complete on disk before its row.
            try {
                writeFileAtomic(file, std::string(png.begin(), png.end()));
            } catch (const std::exception &e) {
                throw Error(std::string("record: ") + e.what() + onDisk());
            }
            encodeMs += std::chrono::duration<double, std::milli>(t1 - t0).count();
            writeMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
        }
    }

    // Rows of the finished frames at the head of the order, once a batch is full, the
    // interval has passed, or someone waits for them.
    void commitLoop() {
        std::unique_lock<std::mutex> lock(mutex);
        auto readyCount = [&] {
            size_t n = 0;
            while (n < inOrder.size() && inOrder[n]->done) ++n;
            return n;
        };
        for (;;) {
            jobDone.wait_for(lock, std::chrono::milliseconds(options.sync_interval_ms), [&] {
                const size_t ready = readyCount();
                return ready >= static_cast<size_t>(options.sync_batch_frames) ||
                       ((flushRequested || committerStopping) && ready > 0) || (committerStopping && inOrder.empty()) ||
                       !error.empty();
            });
            std::vector<std::shared_ptr<Job>> batch;
            for (size_t n = readyCount(), i = 0; i < n && error.empty(); ++i) {
                if (!inOrder.front()->error.empty()) {
                    error = inOrder.front()->error;
                    break;
                }
                batch.push_back(inOrder.front());
                inOrder.pop_front();
            }
            if (!batch.empty()) {
                lock.unlock();
                std::string failure;
                try {
                    writeRows(batch);
                } catch (const std::exception &e) {
                    failure = e.what();
                }
                lock.lock();
                if (failure.empty()) {
                    rows += static_cast<int64_t>(batch.size());
                    ++stats.syncs;
                } else {
                    if (error.empty()) error = failure;
                    // Their rows never made it: their images are orphans too.
                    inOrder.insert(inOrder.begin(), batch.begin(), batch.end());
                }
            }
            if (!error.empty()) {
                // Nothing after a failure is listed. The images written for frames that
                // will never have a row go (on a full disk they hold the room the summary
                // needs); frames still being written are removed by their worker.
                std::vector<std::shared_ptr<Job>> orphans;
                for (const auto &job : inOrder)
                    if (job->done) orphans.push_back(job);
                inOrder.clear();
                committed.notify_all();
                roomAvailable.notify_all();
                lock.unlock();
                removeImages(orphans);
                return; // the workers finish (or skip) their queue on their own
            }
            if (rows == submitted) flushRequested = false;
            committed.notify_all();
            if (committerStopping && inOrder.empty()) return;
        }
    }

    void removeImages(const std::vector<std::shared_ptr<Job>> &jobs) const {
        std::error_code ec;
        for (const auto &job : jobs)
            for (int i = 0; i < 2; ++i) fs::remove(fs::path(dir) / recording::imagePath(i, job->sequence), ec);
    }

    void writeRows(const std::vector<std::shared_ptr<Job>> &batch) {
        std::vector<recording::Row> rows;
        for (const auto &job : batch) rows.push_back(recording::rowFor(job->sequence, job->tl, job->tr));
        const off_t before = ::lseek(csvFd, 0, SEEK_END);
        try {
            recording::appendRowsDurably(csvFd, dirFds, rows, dir);
        } catch (const std::exception &e) {
            // A row cut short by a full disk would be a corrupt last line: the index goes
            // back to its last complete row.
            if (before >= 0 && ::ftruncate(csvFd, before) == 0) ::fsync(csvFd);
            throw Error(std::string("record: ") + e.what() + onDisk());
        }
    }

    std::string onDisk() const {
        const std::string disk = diskOf(dir);
        return disk.empty() ? "" : "; " + disk;
    }

    void rethrow() const {
        if (!error.empty()) throw Error(error);
    }
};

RecordingWriter::RecordingWriter(const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
                                 const RecordingWriterOptions &options)
    : dir_(dir), pool_(std::make_unique<Pool>()) {
    Pool &p = *pool_;
    p.dir = dir;
    p.options = options;
    if (p.options.png_compression < 0 || p.options.png_compression > 9)
        throw Error("record: PNG compression level = " + std::to_string(p.options.png_compression) + ": expected 0..9");
    // Each image waits for its fsync (I/O, not CPU): twice as many threads as cores keep
    // the cores encoding meanwhile.
    if (p.options.threads <= 0) p.options.threads = std::clamp(2 * static_cast<int>(std::thread::hardware_concurrency()), 4, 16);
    if (p.options.queue_frames <= 0) p.options.queue_frames = 8 * p.options.threads;
    p.options.sync_batch_frames = std::max(1, p.options.sync_batch_frames);
    p.options.sync_interval_ms = std::max(1, p.options.sync_interval_ms);
    p.stats.threads = p.options.threads;
    p.stats.png_compression = p.options.png_compression;
    p.stats.queue_frames = p.options.queue_frames;

    std::error_code ec;
    if (fs::exists(dir_, ec)) {
        if (!fs::is_directory(dir_, ec)) throw Error("record: " + dir_ + " exists and is not a folder");
        if (!entriesOf(dir_).empty())
            throw Error("record: " + dir_ + " is not empty (it holds " + listEntries(dir_) +
                        "): refusing to record over it; choose a new folder");
    }
    fs::create_directories(fs::path(dir_) / recording::kSideFolders[0], ec);
    if (!ec) fs::create_directories(fs::path(dir_) / recording::kSideFolders[1], ec);
    if (ec) throw Error("record: cannot create " + dir_ + ": " + ec.message());
    if (!calibrationYaml.empty()) writeFileAtomic((fs::path(dir_) / recording::kCalibrationFile).string(), calibrationYaml);
    if (!rigYaml.empty()) writeFileAtomic((fs::path(dir_) / recording::kRigFile).string(), rigYaml);
    for (int i = 0; i < 2; ++i) {
        const std::string side = (fs::path(dir_) / recording::kSideFolders[i]).string();
        p.dirFds[i] = ::open(side.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (p.dirFds[i] < 0) throw Error("record: cannot open " + side + ": " + std::strerror(errno));
    }
    p.csvPath = (fs::path(dir_) / recording::kIndexFile).string();
    // O_EXCL: even a recorder racing for the same folder cannot truncate another's index.
    p.csvFd = ::open(p.csvPath.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_APPEND | O_CLOEXEC, 0644);
    if (p.csvFd < 0) throw Error("record: cannot create " + p.csvPath + ": " + std::strerror(errno));
    recording::appendDurably(p.csvFd, recording::kIndexHeader, p.csvPath);

    for (int i = 0; i < p.options.threads; ++i) p.workers.emplace_back([&p] { p.work(); });
    p.committer = std::thread([&p] { p.commitLoop(); });
}

RecordingWriter::~RecordingWriter() {
    Pool &p = *pool_;
    {
        std::lock_guard<std::mutex> lock(p.mutex);
        p.stopping = true;
    }
    p.workAvailable.notify_all();
    for (auto &t : p.workers) t.join();
    {
        std::lock_guard<std::mutex> lock(p.mutex);
        p.committerStopping = true;
    }
    p.jobDone.notify_all();
    p.committer.join();
}

bool RecordingWriter::submit(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, cv::Mat left, cv::Mat right,
                             bool rgb, bool wait) {
    Pool &p = *pool_;
    auto job = std::make_shared<Pool::Job>();
    job->sequence = sequence;
    job->tl = timestampLeftNs;
    job->tr = timestampRightNs;
    job->images[0] = std::move(left);
    job->images[1] = std::move(right);
    job->rgb = rgb;
    {
        std::unique_lock<std::mutex> lock(p.mutex);
        p.rethrow();
        if (p.inMemory >= p.options.queue_frames) {
            if (!wait) return false;
            p.roomAvailable.wait(lock, [&] { return p.inMemory < p.options.queue_frames || !p.error.empty(); });
            p.rethrow();
        }
        p.todo.push_back(job);
        p.inOrder.push_back(job);
        ++p.inMemory;
        ++p.submitted;
        p.stats.max_queued = std::max(p.stats.max_queued, p.inMemory);
    }
    p.workAvailable.notify_one();
    return true;
}

bool RecordingWriter::submit(const LentFrame &frame, bool wait) {
    const binocle_stereo_frame &f = frame.raw();
    // Copies: the source's buffers go back as soon as the caller releases the frame.
    const bool rgb = f.left.format == BINOCLE_PIXEL_RGB8 || f.right.format == BINOCLE_PIXEL_RGB8;
    cv::Mat left = recordableView(f.left).clone(), right = recordableView(f.right).clone();
    return submit(f.sequence, f.timestamp_left_ns, f.timestamp_right_ns, std::move(left), std::move(right), rgb, wait);
}

void RecordingWriter::finish() {
    Pool &p = *pool_;
    std::unique_lock<std::mutex> lock(p.mutex);
    p.flushRequested = true;
    p.jobDone.notify_all();
    p.committed.wait(lock, [&] { return p.rows == p.submitted || !p.error.empty(); });
    p.rethrow();
}

void RecordingWriter::append(uint64_t sequence, int64_t timestampLeftNs, int64_t timestampRightNs, const cv::Mat &left,
                             const cv::Mat &right, bool rgb) {
    submit(sequence, timestampLeftNs, timestampRightNs, left.clone(), right.clone(), rgb, true);
    finish();
}

void RecordingWriter::append(const LentFrame &frame) {
    submit(frame, true);
    finish();
}

int64_t RecordingWriter::frameCount() const {
    std::lock_guard<std::mutex> lock(pool_->mutex);
    return pool_->rows;
}

RecordingWriterStats RecordingWriter::stats() const {
    std::lock_guard<std::mutex> lock(pool_->mutex);
    return pool_->stats;
}

namespace {

// A YAML scalar as JSON: integers, reals and booleans as such, anything else as text.
nlohmann::ordered_json jsonOf(const YAML::Node &node) {
    if (node.IsMap()) {
        nlohmann::ordered_json o = nlohmann::ordered_json::object();
        for (const auto &kv : node) o[kv.first.as<std::string>()] = jsonOf(kv.second);
        return o;
    }
    if (node.IsSequence()) {
        nlohmann::ordered_json a = nlohmann::ordered_json::array();
        for (const auto &item : node) a.push_back(jsonOf(item));
        return a;
    }
    if (!node.IsScalar()) return nullptr;
    const std::string text = node.Scalar();
    if (node.Tag() != "!") { // not quoted
        try {
            size_t used = 0;
            const long long i = std::stoll(text, &used);
            if (used == text.size()) return i;
            const double d = std::stod(text, &used);
            if (used == text.size()) return d;
        } catch (const std::exception &) {
        }
        if (text == "true" || text == "false") return text == "true";
    }
    return text;
}

// Counters a source may report (plugin ABI, statistics): images lost in a camera or the
// transport, and images dropped by pairing. The framework names no plugin: it reads these
// keys wherever they are, per camera when a list item has a `role`.
const char *const kTransportKeys[] = {"incomplete_images", "skipped_frame_ids", "corrupt", "dropped_by_driver"};

nlohmann::ordered_json lossesOf(const nlohmann::ordered_json &source) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    if (!source.is_object()) return out;
    if (source.contains("unpaired") && source["unpaired"].is_number_integer()) out["unpaired_images"] = source["unpaired"];
    auto camera = [&](const nlohmann::ordered_json &item) {
        nlohmann::ordered_json c = nlohmann::ordered_json::object();
        int64_t transport = 0;
        bool any = false;
        for (const char *key : kTransportKeys)
            if (item.contains(key) && item[key].is_number_integer()) {
                transport += item[key].get<int64_t>();
                any = true;
            }
        if (any) c["lost_in_camera_or_transport"] = transport;
        if (item.contains("unpaired") && item["unpaired"].is_number_integer()) c["lost_in_pairing"] = item["unpaired"];
        if (any && item.contains("images") && item["images"].is_number_integer())
            c["images_sent"] = item["images"].get<int64_t>() + transport;
        return c;
    };
    for (const auto &[key, value] : source.items()) {
        if (!value.is_array()) continue;
        for (const auto &item : value)
            if (item.is_object() && item.contains("role")) {
                nlohmann::ordered_json c = camera(item);
                if (c.empty()) continue;
                out["cameras"][item["role"].is_string() ? item["role"].get<std::string>() : item["role"].dump()] = c;
            }
    }
    return out;
}

} // namespace

nlohmann::ordered_json recordingSummary(const RecordResult &r) {
    nlohmann::ordered_json j;
    j["status"] = r.status;
    j["pairs_taken"] = r.grabbed;
    j["pairs_written"] = r.frames;
    j["seconds"] = r.seconds;
    j["pairs_written_per_s"] = r.seconds > 0 ? r.frames / r.seconds : 0.0;
    nlohmann::ordered_json source = nullptr;
    if (!r.source_statistics.empty()) {
        try {
            source = jsonOf(YAML::Load(r.source_statistics));
        } catch (const std::exception &) {
            source = r.source_statistics; // not YAML: kept as text
        }
    }
    nlohmann::ordered_json lost = lossesOf(source);
    lost["pairs_dropped_by_writer"] = r.dropped_by_writer;
    lost["when_writers_behind"] = r.dropped_when_behind ? "drop" : "wait";
    j["lost"] = lost;
    const int64_t images = 2 * (r.frames > 0 ? r.frames : 1);
    j["writer"] = {{"threads", r.writer.threads},
                   {"png_compression", r.writer.png_compression},
                   {"queue_frames", r.writer.queue_frames},
                   {"max_queued_frames", r.writer.max_queued},
                   {"row_syncs", r.writer.syncs},
                   {"encode_ms_per_image", r.writer.encode_ms / images},
                   {"write_ms_per_image", r.writer.write_ms / images}};
    j["source_statistics"] = source;
    if (!r.error.empty()) j["error"] = r.error;
    return j;
}

RecordingSinkFactory folderRecordingSink() {
    return [](const std::string &dir, const std::string &calibrationYaml, const std::string &rigYaml,
              const RecordingWriterOptions &options) -> std::unique_ptr<RecordingSink> {
        return std::make_unique<RecordingWriter>(dir, calibrationYaml, rigYaml, options);
    };
}

namespace {

// The recording loop, the same for every sink: grabs as the pipeline's acquire stage does
// (grabWithin), hands each pair to the sink, ends on max_frames, a stop or the stream's end.
RecordResult recordInto(RecordingSink &sink, Source &source, const std::string &dir, const RecordOptions &options,
                        const std::function<void(int64_t frames)> &onFrame) {
    RecordResult result;
    result.dropped_when_behind = options.drop_when_behind.value_or(sourceIsLive(source));
    const auto begin = std::chrono::steady_clock::now();
    Progress progress(options.progress, "frame", options.max_frames);
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(); };
    auto stopped = [&] { return options.stop && options.stop->load(); };
    try {
        source.start();
        while (options.max_frames < 0 || result.grabbed < options.max_frames) {
            if (stopped()) {
                result.status = "interrupted";
                break;
            }
            std::unique_ptr<LentFrame> frame;
            try {
                frame = grabWithin(source, options.grab_timeout_ms, stopped);
            } catch (const PluginError &e) {
                if (!stopped() || e.code() != BINOCLE_ERR_TIMEOUT) throw;
                result.status = "interrupted"; // asked to stop while the source was silent
                break;
            }
            if (!frame) break;
            ++result.grabbed;
            if (!sink.submit(*frame, !result.dropped_when_behind)) ++result.dropped_by_writer;
            frame.reset(); // the copy is queued: the source has its buffers back
            if (onFrame) onFrame(result.grabbed);
            progress.update(sink.frameCount(), "recorded, " + std::to_string(result.dropped_by_writer) +
                                                   " dropped (writers behind)");
        }
        source.stop();
    } catch (const std::exception &e) {
        result.error = e.what();
        result.status = "error";
        try {
            source.stop(); // a camera is let go at once, not when the summary is written
        } catch (const std::exception &) {
        }
    }
    try {
        sink.finish();
    } catch (const std::exception &e) {
        if (result.error.empty()) result.error = e.what();
        result.status = "error";
    }
    progress.finish();
    try {
        result.source_statistics = source.statistics();
    } catch (const std::exception &) {
    }
    result.frames = sink.frameCount();
    result.seconds = elapsed();
    result.writer = sink.stats();
    try {
        writeFileAtomic((fs::path(dir) / "summary.json").string(), recordingSummary(result).dump(2) + "\n");
    } catch (const std::exception &e) {
        spdlog::warn("record: {}", e.what());
    }
    return result;
}

} // namespace

RecordResult recordRig(const RigConfig &rig, const std::string &dir, const RecordOptions &options,
                       const std::function<void(int64_t frames)> &onFrame) {
    Source source(*rig.source().record, rig.source().params, rig.source().isolation);
    std::string calibration;
    if (rig.calibration_file) calibration = readTextFile(*rig.calibration_file);
    else calibration = source.calibration();
    const RecordingSinkFactory &make = options.sink ? options.sink : folderRecordingSink();
    std::unique_ptr<RecordingSink> sink = make(dir, calibration, rig.resolved_yaml, options.writer);
    return recordInto(*sink, source, dir, options, onFrame);
}

} // namespace binocle
