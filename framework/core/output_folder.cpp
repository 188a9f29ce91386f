// SPDX-License-Identifier: MIT
// Output-folder ownership: a lock file held with flock, and the kind of output a folder holds.
#include "core/output_folder.hpp"

#include "core/error.hpp"

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

} // namespace

std::string describe(OutputKind kind) {
    switch (kind) {
    case OutputKind::None: return "nothing Binocle wrote";
    case OutputKind::Run: return "the output of a run (frames.jsonl)";
    case OutputKind::Recording: return "a recording (frames.csv)";
    case OutputKind::Experiment: return "an experiment's results (results.json)";
    }
    return "?";
}

OutputKind outputKindOf(const std::string &dir) {
    const fs::path d(dir);
    // A recording first: it is the one a user can least afford to lose.
    if (isFile(d / "frames.csv")) return OutputKind::Recording;
    if (isFile(d / "results.json") || isFile(d / "results.csv")) return OutputKind::Experiment;
    if (isFile(d / "frames.jsonl")) return OutputKind::Run;
    return OutputKind::None;
}

OutputFolder::OutputFolder(const std::string &dir, const OutputClaim &claim) : dir_(dir) {
    if (dir.empty()) throw Error("output folder: empty path");
    std::error_code ec;
    const auto status = fs::symlink_status(dir, ec);
    if (fs::exists(status) && !fs::is_directory(fs::status(dir, ec)))
        throw Error("output folder " + dir + ": exists and is not a folder");
    created_ = !fs::exists(status);
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
    std::error_code ec;
    const OutputKind held = outputKindOf(dir);
    if (claim.kind == OutputKind::None || held == OutputKind::None || held == claim.kind) return;
    if (!claim.force) {
        throw Error("output folder " + dir + " holds " + describe(held) + ": refusing to write " + describe(claim.kind) +
                    " into it; choose another folder, or pass --force to replace what it holds");
    }
    // Replace: everything but the lock goes; entries are removed, never followed.
    for (const auto &e : fs::directory_iterator(dir, ec)) {
        if (e.path().filename() == kLockFile) continue;
        fs::remove_all(e.path(), ec);
        if (ec) throw Error("output folder " + dir + ": --force: cannot remove " + e.path().string() + ": " + ec.message());
    }
    if (ec) throw Error("output folder " + dir + ": cannot list the folder: " + ec.message());
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
    // before its first output) goes again; rmdir leaves any folder that holds something.
    if (created_) ::rmdir(dir_.c_str());
}

} // namespace binocle
