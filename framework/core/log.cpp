// SPDX-License-Identifier: MIT
// Logging set-up (spdlog) and the route of plugins' messages into it.
#include "core/log.hpp"

#include "core/error.hpp"
#include "core/progress.hpp"

#include <binocle/abi.h>

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <mutex>

namespace binocle {

namespace {

// "%*" in a pattern: nothing for info (the message speaks for itself, as command output
// always did), "<program>: <level>: " for every other level.
class LevelPrefix : public spdlog::custom_flag_formatter {
public:
    explicit LevelPrefix(std::string program) : program_(std::move(program)) {}
    void format(const spdlog::details::log_msg &msg, const std::tm &, spdlog::memory_buf_t &dest) override {
        if (msg.level == spdlog::level::info) return;
        static const char *names[] = {"trace", "debug", "info", "warning", "error", "critical", "off"};
        const std::string text = program_ + ": " + names[std::clamp<int>(msg.level, 0, 6)] + ": ";
        dest.append(text.data(), text.data() + text.size());
    }
    std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<LevelPrefix>(program_); }

private:
    std::string program_;
};

// "%~" in a pattern: the message with its control characters escaped (\x1b, and the C1
// controls U+0080..U+009F as \u0080). The one place every logged text passes, so a name
// from a file (a bag's topic, a plugin's message) can never drive the terminal: move the
// cursor, retitle the window or hide a line. Line breaks and tabs stay as they are.
class EscapedMessage : public spdlog::custom_flag_formatter {
public:
    void format(const spdlog::details::log_msg &msg, const std::tm &, spdlog::memory_buf_t &dest) override {
        const char *p = msg.payload.data();
        const size_t n = msg.payload.size();
        char hex[8];
        for (size_t i = 0; i < n; ++i) {
            const auto c = static_cast<unsigned char>(p[i]);
            if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7f) {
                std::snprintf(hex, sizeof hex, "\\x%02x", c);
                dest.append(hex, hex + 4);
            } else if (c == 0xc2 && i + 1 < n && static_cast<unsigned char>(p[i + 1]) >= 0x80 &&
                       static_cast<unsigned char>(p[i + 1]) <= 0x9f) {
                std::snprintf(hex, sizeof hex, "\\u%04x", static_cast<unsigned char>(p[++i]));
                dest.append(hex, hex + 6);
            } else {
                dest.push_back(static_cast<char>(c));
            }
        }
    }
    std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<EscapedMessage>(); }
};

// stderr, clearing a live progress line first so that a message never lands in its middle.
class StderrSink : public spdlog::sinks::base_sink<std::mutex> {
protected:
    void sink_it_(const spdlog::details::log_msg &msg) override {
        spdlog::memory_buf_t out;
        formatter_->format(msg, out);
        Progress::clearLiveLine();
        std::fwrite(out.data(), 1, out.size(), stderr);
        std::fflush(stderr);
    }
    void flush_() override { std::fflush(stderr); }
};

} // namespace

spdlog::level::level_enum parseLogLevel(const std::string &text, const std::string &what) {
    std::string t = text;
    std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (t == "warning") t = "warn";
    static const char *names[] = {"trace", "debug", "info", "warn", "error", "critical", "off"};
    for (int i = 0; i < 7; ++i)
        if (t == names[i]) return static_cast<spdlog::level::level_enum>(i);
    throw Error(what + " '" + text + "': expected one of trace, debug, info, warn, error, critical, off");
}

void setupLogging(const LogOptions &options) {
    auto console = std::make_shared<StderrSink>();
    auto consoleFormat = std::make_unique<spdlog::pattern_formatter>();
    consoleFormat->add_flag<LevelPrefix>('*', options.program).add_flag<EscapedMessage>('~').set_pattern("%*%~");
    console->set_formatter(std::move(consoleFormat));
    std::vector<spdlog::sink_ptr> sinks{console};
    if (!options.file.empty()) {
        try {
            auto file = std::make_shared<spdlog::sinks::basic_file_sink_mt>(options.file);
            auto fileFormat = std::make_unique<spdlog::pattern_formatter>();
            fileFormat->add_flag<EscapedMessage>('~').set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] %~");
            file->set_formatter(std::move(fileFormat));
            sinks.push_back(file);
        } catch (const spdlog::spdlog_ex &e) {
            throw Error("--log-file " + options.file + ": cannot open it: " + e.what());
        }
    }
    auto logger = std::make_shared<spdlog::logger>("binocle", sinks.begin(), sinks.end());
    logger->set_level(options.level);
    // Warnings and errors reach the file at once, even if the process dies afterwards.
    logger->flush_on(spdlog::level::warn);
    spdlog::set_default_logger(logger);
}

void logFromPlugin(const std::string &plugin, int32_t level, const std::string &message) {
    spdlog::level::level_enum l = spdlog::level::info;
    if (level <= BINOCLE_LOG_DEBUG) l = spdlog::level::debug;
    else if (level == BINOCLE_LOG_WARNING) l = spdlog::level::warn;
    else if (level >= BINOCLE_LOG_ERROR) l = spdlog::level::err;
    spdlog::log(l, "[{}] {}", plugin, message);
}

} // namespace binocle
