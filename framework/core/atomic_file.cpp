// SPDX-License-Identifier: MIT
// Whole-file reads and crash-safe writes.
#include "core/atomic_file.hpp"

#include "core/error.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
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

std::string temporaryFor(const std::string &path) {
    fs::path p(path);
    return (p.parent_path() / (".tmp-" + std::to_string(::getpid()) + "-" + p.filename().string())).string();
}

void commit(const std::string &tmp, const std::string &path) {
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error("cannot write " + path + ": rename failed: " + ec.message());
    }
}

} // namespace

void writeFileAtomic(const std::string &path, const std::string &bytes) {
    writeFileAtomicWith(path, [&](const std::string &tmp) {
        FILE *f = std::fopen(tmp.c_str(), "wb");
        if (!f) throw Error("cannot write " + path + ": " + std::strerror(errno));
        const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 &&
                        ::fsync(::fileno(f)) == 0;
        const int err = errno;
        std::fclose(f);
        if (!ok) throw Error("cannot write " + path + ": " + std::strerror(err));
    });
}

void writeFileAtomicWith(const std::string &path, const std::function<void(const std::string &tmp)> &write) {
    const std::string tmp = temporaryFor(path);
    try {
        write(tmp);
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    if (!fs::exists(tmp)) throw Error("cannot write " + path + ": the writer produced no file");
    commit(tmp, path);
}

} // namespace binocle
