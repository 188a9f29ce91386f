// SPDX-License-Identifier: MIT
// Whole-file reads and crash-safe writes.
#include "core/atomic_file.hpp"

#include "core/error.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
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

// Creates "<dir>/.tmp-<random>-<name>" that did not exist: O_CREAT|O_EXCL never opens a
// file or a symbolic link planted there (O_NOFOLLOW says so twice), and the random part
// leaves nothing to plant in advance. Returns the open descriptor.
int createTemporary(const std::string &path, std::string &tmp) {
    const fs::path p(path);
    static thread_local std::mt19937_64 random{std::random_device{}()};
    for (int attempt = 0; attempt < 100; ++attempt) {
        char suffix[17];
        std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(random()));
        tmp = (p.parent_path() / (".tmp-" + std::string(suffix) + "-" + p.filename().string())).string();
        const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0) return fd;
        if (errno != EEXIST) throw Error("cannot write " + path + ": " + std::strerror(errno));
    }
    throw Error("cannot write " + path + ": no free temporary name beside it");
}

void commit(const std::string &tmp, const std::string &path) {
    // rename() replaces `path` itself, even when it is a symbolic link: it writes through
    // nothing planted there.
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": rename failed: " + ec.message());
    }
}

} // namespace

void writeFileAtomic(const std::string &path, const std::string &bytes) {
    std::string tmp;
    const int fd = createTemporary(path, tmp);
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        done += static_cast<size_t>(n);
    }
    const bool ok = done == bytes.size() && ::fsync(fd) == 0;
    const int err = errno;
    ::close(fd);
    if (!ok) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": " + std::strerror(err));
    }
    commit(tmp, path);
}

} // namespace binocle
