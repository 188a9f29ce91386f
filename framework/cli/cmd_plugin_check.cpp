// SPDX-License-Identifier: MIT
// `binocle plugin-check FILE.so|NAME`: the conformance kit (framework/conformance) for
// plugin authors; thin parsing only.
#include "cli/command.hpp"
#include "conformance/conformance.hpp"
#include "files/atomic_file.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

struct PluginCheckArgs {
    ConformanceOptions options;
    long long timeout_ms = 20000;
    std::string junit;
};

int checkPluginCommand(PluginCheckArgs &args) {
    args.options.case_timeout_ms = static_cast<int32_t>(args.timeout_ms);
    ConformanceReport report;
    try {
        report = checkPlugin(args.options);
    } catch (const SettingsRefused &e) {
        throw UsageError(e.what()); // exit status 2: no case ran with settings not meant
    }
    static const char *words[] = {"PASS", "FAIL", "SKIP"};
    std::cout << "plugin-check " << report.path << (report.kind.empty() ? "" : " (" + report.kind + " '" + report.plugin + "')")
              << "\n";
    for (const auto &c : report.cases)
        std::cout << "  " << words[static_cast<int>(c.status)] << "  " << c.name << (c.message.empty() ? "" : ": " + c.message) << "\n";
    std::cout << report.summary() << "\n";
    if (!args.junit.empty()) writeFileAtomic(args.junit, junitXml(report));
    return report.passed() ? kExitOk : kExitFailed;
}

Register pluginCheckCommand{{"plugin-check", "check a plugin against the ABI's rules (conformance kit), JUnit report",
              "Runs the conformance battery of the plugin's kind, each case in a child process\n"
              "(a crash or a hang is a failed case, with the signal or the timeout):\n"
              "  all kinds   load (in a child first; RTLD_NOW), table, settings, create/destroy\n"
              "              cycles, determinism where it applies\n"
              "  matcher     compute with guard pages around every buffer and read-only\n"
              "              inputs, colour formats, calls the host never makes answered with\n"
              "              a code and a message, disparity_range\n"
              "  source      enumerate_devices, grab before start, lend/release accounting,\n"
              "              release from another thread, BUSY, END_OF_STREAM, calibration\n"
              "  transform   apply inside the host's arrays, empty cloud\n"
              "  evaluator   evaluate on read-only guarded inputs\n"
              "A source that needs a device it cannot find has its instance cases skipped,\n"
              "saying why; skipped cases are counted apart and never read as a pass.\n"
              "Exit status 0 when no case failed, 1 otherwise, 2 for a --set the plugin\n"
              "refuses (an unknown key or a bad value).",
              define<PluginCheckArgs>(
                  [](CLI::App &app, PluginCheckArgs &args) {
                      app.add_option("plugin", args.options.plugin, "the plugin file (FILE.so) or name (binocle_NAME.so in the search path)")
                          ->required()
                          ->type_name("FILE.so|NAME");
                      app.add_option("--set", args.options.settings, "a setting given to create (repeatable), e.g. --set window_px=7")
                          ->type_name("KEY=VALUE")
                          ->allow_extra_args(false);
                      app.add_option("--junit", args.junit, "write a JUnit XML report for CI")->type_name("FILE");
                      app.add_option("--timeout-ms", args.timeout_ms, "a case running longer fails (default 20000)")->check(atLeast(100));
                  },
                  checkPluginCommand)}};

} // namespace
} // namespace binocle::cli
