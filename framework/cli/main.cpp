// SPDX-License-Identifier: MIT
// `binocle`: parses the command line (CLI11), sets up logging, runs the chosen command.
#include "cli/command.hpp"
#include "config/rig_config.hpp"
#include "core/log.hpp"
#include "input/image_file.hpp"
#include "input/names.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <iostream>

namespace {

using namespace binocle;
using namespace binocle::cli;

// Every spelling of the options of `app` and of the top level (global options).
std::vector<std::string> optionNames(const CLI::App &app) {
    std::vector<std::string> names;
    for (const CLI::App *a = &app; a; a = a->get_parent())
        for (const CLI::Option *o : a->get_options()) {
            for (const auto &l : o->get_lnames()) names.push_back("--" + l);
            for (const auto &s : o->get_snames()) names.push_back("-" + s);
        }
    return names;
}

// What CLI11 left unparsed, as one message: the first unknown option (with the nearest
// known one) or the first argument too many.
std::string extrasMessage(const CLI::App &app, const std::vector<std::string> &extras) {
    for (const auto &x : extras) {
        if (x.size() < 2 || x[0] != '-') continue;
        const std::string name = x.substr(0, x.find('='));
        std::vector<std::string> bare;
        const std::vector<std::string> names = optionNames(app);
        for (const auto &n : names) bare.push_back(n.substr(n.find_first_not_of('-')));
        const std::string hint = input::nearestWord(name.substr(name.find_first_not_of('-')), bare);
        std::string suggestion;
        for (size_t i = 0; i < bare.size() && !hint.empty(); ++i)
            if (bare[i] == hint) suggestion = names[i];
        return "unknown option '" + name + "'" + (suggestion.empty() ? "" : "; did you mean '" + suggestion + "'?");
    }
    return "unexpected argument '" + extras.front() + "'";
}

LogOptions plainLog(const std::string &program) {
    LogOptions o;
    o.program = program;
    return o;
}

} // namespace

int main(int argc, char **argv) {
    // OpenCV's own limit for the formats input/image_file.cpp does not read a header of
    // (TIFF, WebP, ...): the same pixel count, before OpenCV first reads it.
    ::setenv("OPENCV_IO_MAX_IMAGE_PIXELS", std::to_string(input::kMaxImagePixels).c_str(), 0);
    std::map<const CLI::App *, Runner> runners;
    std::unique_ptr<CLI::App> app = makeApp(runners);
    std::string logLevel = "info", logFile;
    app->add_option("--log-level", logLevel, "trace, debug, info, warn, error or off (default info)")
        ->envname("BINOCLE_LOG_LEVEL")
        ->type_name("LEVEL");
    app->add_option("--log-file", logFile, "also write the log (every level shown, with times) to FILE")->type_name("FILE");

    setupLogging(plainLog("binocle"));
    if (argc < 2) {
        std::cerr << app->help();
        return kExitUsage;
    }
    if (std::string(argv[1]) == "help") {
        std::cout << app->help();
        return kExitOk;
    }
    try {
        app->parse(argc, argv);
    } catch (const CLI::CallForHelp &e) {
        return app->exit(e);
    } catch (const CLI::CallForAllHelp &e) {
        return app->exit(e);
    } catch (const CLI::CallForVersion &e) {
        return app->exit(e);
    } catch (const CLI::ParseError &e) {
        std::string program = "binocle";
        for (const CLI::App *sub : app->get_subcommands()) program += " " + sub->get_name();
        setupLogging(plainLog(program));
        spdlog::error("{} (see `{} --help`)", e.what(), program);
        return kExitUsage;
    }
    const std::vector<CLI::App *> chosen = app->get_subcommands();
    const CLI::App *sub = chosen.empty() ? nullptr : chosen.front();
    const std::string program = sub ? "binocle " + sub->get_name() : "binocle";
    try {
        setupLogging({program, parseLogLevel(logLevel, "--log-level"), logFile});
    } catch (const std::exception &e) {
        setupLogging(plainLog(program));
        spdlog::error("{}", e.what());
        return kExitUsage;
    }
    const std::vector<std::string> extras = app->remaining(true);
    if (!sub) {
        if (extras.empty()) {
            std::cerr << app->help();
            return kExitUsage;
        }
        std::vector<std::string> names;
        for (const auto &[name, c] : commands()) names.push_back(name);
        const std::string hint = input::nearestWord(extras.front(), names);
        spdlog::error("unknown command '{}'{} (see `binocle --help`)", extras.front(),
                      hint.empty() ? "" : "; did you mean '" + hint + "'?");
        return kExitUsage;
    }
    if (!extras.empty()) {
        spdlog::error("{} (see `{} --help`)", extrasMessage(*sub, extras), program);
        return kExitUsage;
    }
    try {
        return runners.at(sub)();
    } catch (const UsageError &e) {
        spdlog::error("{} (see `{} --help`)", e.what(), program);
        return kExitUsage;
    } catch (const std::exception &e) {
        spdlog::error("{}", e.what());
        return kExitFailed;
    }
}
