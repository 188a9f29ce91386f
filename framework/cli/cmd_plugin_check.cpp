// SPDX-License-Identifier: MIT
// `binocle plugin-check FILE.so|NAME`: the conformance kit (framework/conformance) for
// plugin authors; thin parsing only.
#include "cli/command.hpp"
#include "conformance/conformance.hpp"
#include "core/atomic_file.hpp"

#include <iostream>

namespace binocle::cli {
namespace {

int run(const Args &args) {
    if (args.positional().size() != 1) throw Error("expected one plugin: binocle plugin-check FILE.so|NAME (see --help)");
    ConformanceOptions options;
    options.plugin = args.positional()[0];
    options.settings = args.all("--set");
    options.case_timeout_ms = static_cast<int32_t>(args.integer("--timeout-ms", options.case_timeout_ms));
    if (options.case_timeout_ms < 100) throw Error("option --timeout-ms = " + args.get("--timeout-ms") + ": expected at least 100");
    const ConformanceReport report = checkPlugin(options);
    static const char *words[] = {"PASS", "FAIL", "SKIP"};
    std::cout << "plugin-check " << report.path << (report.kind.empty() ? "" : " (" + report.kind + " '" + report.plugin + "')")
              << "\n";
    for (const auto &c : report.cases)
        std::cout << "  " << words[static_cast<int>(c.status)] << "  " << c.name << (c.message.empty() ? "" : ": " + c.message) << "\n";
    using S = ConformanceCase::Status;
    std::cout << report.count(S::Passed) << " passed, " << report.count(S::Failed) << " failed, " << report.count(S::Skipped)
              << " skipped\n";
    if (args.has("--junit")) writeFileAtomic(args.get("--junit"), junitXml(report));
    return report.passed() ? 0 : 1;
}

Register reg({"plugin-check", "check a plugin against the ABI's rules (conformance kit), JUnit report",
              "usage: binocle plugin-check FILE.so|NAME [--set KEY=VALUE]... [--junit FILE] [--timeout-ms N]\n\n"
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
              "saying why. Exit status 0 when no case failed.\n\n"
              "  --set KEY=VALUE  a setting given to create (repeatable), e.g. --set window_px=7\n"
              "  --junit FILE     write a JUnit XML report for CI\n"
              "  --timeout-ms N   a case running longer fails (default 20000)\n",
              {},
              run});

} // namespace
} // namespace binocle::cli
