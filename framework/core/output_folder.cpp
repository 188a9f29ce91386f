// SPDX-License-Identifier: MIT
// Output-folder ownership: a lock file held with flock, and the kind of output a folder holds.
#include "core/output_folder.hpp"

#include "files/atomic_file.hpp"
#include "core/error.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle {

namespace {

bool isFile(const fs::path &p) {
    std::error_code ec;
    return fs::is_regular_file(fs::symlink_status(p, ec));
}

// The lock file's text: "pid command", at most a line; what another process wrote is
// read capped and shown only as a number and a command name.
std::string ownerOf(int fd) {
    char buf[256] = {};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    if (n <= 0) return "another process";
    std::string text(buf, static_cast<size_t>(n));
    text = text.substr(0, text.find('\n'));
    const size_t space = text.find(' ');
    const std::string pid = text.substr(0, space);
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) return "another process";
    std::string command = space == std::string::npos ? "" : text.substr(space + 1);
    for (char &c : command)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    return "process " + pid + (command.empty() ? "" : " (" + command + ")");
}

struct KindName {
    OutputKind kind;
    const char *name, *what;
};
constexpr KindName kKinds[] = {{OutputKind::Run, "run", "the output of a run"},
                               {OutputKind::Recording, "recording", "a recording"},
                               {OutputKind::Experiment, "experiment", "an experiment's results"},
                               {OutputKind::Design, "design", "a design's ranking"},
                               {OutputKind::View, "view", "the viewer's snapshots"}};

// The marker's kind and command; kind None when there is no marker (or not one of ours).
std::pair<OutputKind, std::string> markerOf(const fs::path &dir) {
    const fs::path marker = dir / OutputFolder::kMarkerFile;
    if (!isFile(marker)) return {OutputKind::None, ""};
    char buf[256] = {};
    const int fd = ::open(marker.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return {OutputKind::None, ""};
    const ssize_t n = ::read(fd, buf, sizeof buf - 1);
    ::close(fd);
    std::string text(buf, n > 0 ? static_cast<size_t>(n) : 0);
    text = text.substr(0, text.find('\n'));
    const size_t space = text.find(' ');
    const std::string name = text.substr(0, space);
    std::string command = space == std::string::npos ? "" : text.substr(space + 1);
    for (char &c : command)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    for (const KindName &k : kKinds)
        if (name == k.name) return {k.kind, command};
    return {OutputKind::None, ""};
}

// Recognised by the files each command writes first (folders made before the marker).
std::pair<OutputKind, std::string> recognised(const fs::path &d) {
    // A recording first: it is the one a user can least afford to lose.
    if (isFile(d / "frames.csv")) return {OutputKind::Recording, "frames.csv"};
    if (isFile(d / "metadata.yaml")) return {OutputKind::Recording, "a rosbag2 bag: metadata.yaml"};
    std::error_code ec;
    for (const auto &e : fs::directory_iterator(d, ec))
        if (e.path().extension() == ".mcap") return {OutputKind::Recording, "an MCAP file: " + e.path().filename().string()};
    if (isFile(d / "results.json")) return {OutputKind::Experiment, "results.json"};
    if (isFile(d / "results.csv")) return {OutputKind::Experiment, "results.csv"};
    if (isFile(d / "frames.jsonl")) return {OutputKind::Run, "frames.jsonl"};
    if (isFile(d / "design.json")) return {OutputKind::Design, "design.json"};
    return {OutputKind::None, ""};
}

} // namespace

std::string describe(OutputKind kind) {
    for (const KindName &k : kKinds)
        if (k.kind == kind) return k.what;
    return "nothing Binocle wrote";
}

OutputKind outputKindOf(const std::string &dir) {
    const auto marked = markerOf(dir);
    return marked.first != OutputKind::None ? marked.first : recognised(dir).first;
}

std::vector<std::string> entriesOf(const std::string &dir) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto &e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name != OutputFolder::kLockFile && name != OutputFolder::kMarkerFile) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

std::string listEntries(const std::string &dir, size_t max) {
    const std::vector<std::string> names = entriesOf(dir);
    std::string out;
    for (size_t i = 0; i < names.size() && i < max; ++i) out += (i ? ", " : "") + names[i];
    if (names.size() > max) out += ", ... (" + std::to_string(names.size()) + " entries)";
    return out;
}

std::string describeContent(const std::string &dir) {
    if (entriesOf(dir).empty()) return "";
    const auto [marked, command] = markerOf(dir);
    const auto [kind, file] = recognised(dir);
    if (marked != OutputKind::None)
        return describe(marked) + (kind == marked ? " (" + file + ")" : "") + ", made by " + (command.empty() ? "binocle" : command);
    if (kind != OutputKind::None) return describe(kind) + " (" + file + ")";
    return "files Binocle did not write there (" + listEntries(dir) + ")";
}

OutputFolder::OutputFolder(const std::string &dir, const OutputClaim &claim) : dir_(dir) {
    if (dir.empty()) throw Error("output folder: empty path");
    std::error_code ec;
    const auto status = fs::symlink_status(dir, ec);
    if (fs::exists(status) && !fs::is_directory(fs::status(dir, ec)))
        throw Error("output folder " + dir + ": exists and is not a folder");
    // The folders this claim makes (DIR and any missing parent), deepest first.
    fs::path deepest = fs::path(dir).lexically_normal();
    if (deepest.filename().empty()) deepest = deepest.parent_path(); // "out/view/"
    for (fs::path p = deepest; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
        created_.push_back(p.string());
        if (p == p.parent_path()) break;
    }
    fs::create_directories(dir, ec);
    if (ec) throw Error("output folder " + dir + ": cannot create the folder: " + ec.message());
    lock(claim.command);
    try {
        checkKind(claim);
    } catch (...) {
        release();
        throw;
    }
}

void OutputFolder::checkKind(const OutputClaim &claim) {
    const std::string &dir = dir_;
    if (claim.kind == OutputKind::None) return;
    if (entriesOf(dir).empty() || markerOf(dir).first == claim.kind) return mark(claim);
    const std::string held = describeContent(dir);
    const std::string &flag = claim.force_flag;
    // A recording is never written over: `binocle record` has no --force.
    const bool recording = claim.kind == OutputKind::Recording;
    if (!claim.force || recording) {
        throw Error("output folder " + dir + " holds " + held + ": " + (claim.command.empty() ? "binocle" : claim.command) +
                    " writes " + describe(claim.kind) + " only into a new or empty folder" +
                    (recording ? "; choose another folder" : ", or one it made; choose another folder, or pass " + flag +
                                                                 " to replace what it holds"));
    }
    // Replace: everything but the lock goes; entries are removed, never followed.
    std::error_code ec;
    for (const auto &e : fs::directory_iterator(dir, ec)) {
        if (e.path().filename() == kLockFile) continue;
        fs::remove_all(e.path(), ec);
        if (ec) throw Error("output folder " + dir + ": " + flag + ": cannot remove " + e.path().string() + ": " + ec.message());
    }
    if (ec) throw Error("output folder " + dir + ": cannot list the folder: " + ec.message());
    mark(claim);
}

void OutputFolder::mark(const OutputClaim &claim) {
    for (const KindName &k : kKinds)
        if (k.kind == claim.kind && markerOf(dir_).first != claim.kind)
            writeFileAtomic((fs::path(dir_) / kMarkerFile).string(),
                            std::string(k.name) + " " + (claim.command.empty() ? "binocle" : claim.command) + "\n");
}

void OutputFolder::lock(const std::string &command) {
    lockPath_ = (fs::path(dir_) / kLockFile).string();
    // The lock file is removed by its owner on exit; a process that opened it just before
    // holds a lock on a file no longer in the folder, so after locking the path is checked
    // to still be the file locked, else the claim starts again.
    for (int attempt = 0; attempt < 100; ++attempt) {
        const int fd = ::open(lockPath_.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd < 0)
            throw Error("output folder " + dir_ + ": cannot open its lock file " + lockPath_ + ": " + std::strerror(errno));
        struct stat opened {};
        if (::fstat(fd, &opened) != 0 || !S_ISREG(opened.st_mode)) {
            ::close(fd);
            throw Error("output folder " + dir_ + ": " + lockPath_ + " is not a regular file");
        }
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            const std::string owner = ownerOf(fd);
            ::close(fd);
            if (err == EWOULDBLOCK)
                throw Error("output folder " + dir_ + " is in use by " + owner +
                            ": one process writes into a folder at a time; wait for it to end or choose another folder");
            throw Error("output folder " + dir_ + ": cannot lock " + lockPath_ + ": " + std::strerror(err));
        }
        struct stat now {};
        if (::lstat(lockPath_.c_str(), &now) != 0 || now.st_ino != opened.st_ino || now.st_dev != opened.st_dev) {
            ::close(fd); // removed or replaced meanwhile
            continue;
        }
        const std::string text = std::to_string(::getpid()) + " " + (command.empty() ? "binocle" : command) + "\n";
        if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size())) {
            // A full disk may refuse the pid: the lock holds all the same.
        }
        fd_ = fd;
        return;
    }
    throw Error("output folder " + dir_ + ": its lock file keeps being replaced; is another program writing into it?");
}

OutputFolder::~OutputFolder() { release(); }

void OutputFolder::release() {
    if (fd_ < 0) return;
    // Removed while still locked: a newcomer that opened it meanwhile sees it gone and retries.
    ::unlink(lockPath_.c_str());
    ::close(fd_);
    fd_ = -1;
    // A folder this claim made and nothing was written into (the command was refused
    // before its first output) goes again, marker and all; rmdir leaves any folder that
    // holds something.
    if (!created_.empty() && entriesOf(dir_).empty()) {
        ::unlink((fs::path(dir_) / kMarkerFile).c_str());
        for (const std::string &d : created_)
            if (::rmdir(d.c_str()) != 0) break;
    }
}

} // namespace binocle
