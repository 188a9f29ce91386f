// SPDX-License-Identifier: MIT
// Whole-file reads and crash-safe writes.
#include "files/atomic_file.hpp"

#include "error/error.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fcntl.h>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace binocle {

std::string readTextFile(const std::string &path, uintmax_t maxBytes) {
    // Checked first: std::ifstream opens a folder and then throws
    // "basic_filebuf::underflow" when read.
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw Error("cannot read " + path + ": no such file");
    if (!fs::is_regular_file(status)) throw Error("cannot read " + path + ": not a regular file");
    const uintmax_t size = fs::file_size(path, ec);
    if (!ec && size > maxBytes)
        throw Error("cannot read " + path + ": the file holds " + std::to_string(size) + " bytes; expected at most " +
                    std::to_string(maxBytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read " + path + ": " + std::strerror(errno));
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

namespace {

// A new, empty temporary beside `path`: ".tmp-<pid>-<random>-<file name>" (the extension
// kept for writers that choose the format by it), created with O_EXCL | O_NOFOLLOW so that
// a file or symlink planted under a guessed name is never followed nor reused. The mode
// is the usual 0666 less the umask, as a plain open would give.
int createTemporary(const std::string &path, std::string &tmp) {
    static std::atomic<uint64_t> counter{0};
    const fs::path p(path);
    std::random_device random;
    for (int attempt = 0; attempt < 100; ++attempt) {
        char tag[64];
        std::snprintf(tag, sizeof tag, ".tmp-%d-%08x%04x-", static_cast<int>(::getpid()), random(),
                      static_cast<unsigned>(counter++ & 0xffff));
        tmp = (p.parent_path() / (tag + p.filename().string())).string();
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0) return fd;
        if (errno != EEXIST) throw Error("cannot write " + path + ": cannot create " + tmp + ": " + std::strerror(errno));
    }
    throw Error("cannot write " + path + ": no free temporary name beside it (100 tries)");
}

void commit(const std::string &tmp, const std::string &path) {
    // rename(2) itself, its errno read at once: std::filesystem::rename reported a file
    // renamed over a folder as "Success" (libstdc++ checks the target first).
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        std::error_code ec;
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": rename failed: " + std::strerror(err) +
                    (err == EISDIR || fs::is_directory(path, ec) ? " (it is a folder; expected a file name)" : ""));
    }
}

} // namespace

void writeFileAtomic(const std::string &path, const std::string &bytes) {
    std::string tmp;
    const int fd = createTemporary(path, tmp);
    size_t done = 0;
    int err = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            err = n < 0 ? errno : ENOSPC;
            break;
        }
        done += static_cast<size_t>(n);
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
    ::close(fd);
    if (err != 0) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": " + std::strerror(err));
    }
    commit(tmp, path);
}

void writeFileAtomicWith(const std::string &path, const std::function<void(const std::string &tmp)> &write) {
    std::string tmp;
    ::close(createTemporary(path, tmp)); // the name is ours; the writer opens it again
    try {
        write(tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    if (!fs::exists(tmp, ec) || fs::file_size(tmp, ec) == 0) {
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": the writer produced no file");
    }
    commit(tmp, path);
}

} // namespace binocle
