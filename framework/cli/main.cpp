// SPDX-License-Identifier: MIT
// `binocle`: entry point and subcommand dispatch.
#include "cli/command.hpp"
#include "core/error.hpp"

#include <binocle/abi.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace binocle::cli {

namespace {
std::map<std::string, Command> &registry() {
    static std::map<std::string, Command> r;
    return r;
}
} // namespace

const std::map<std::string, Command> &commands() { return registry(); }

RigConfig loadRigFromArgs(const Args &args, const PluginHost &host) {
    std::vector<Override> overrides;
    for (const auto &s : args.all("--set")) overrides.push_back(Override::parse(s));
    return loadRig(args.positional().at(0), overrides, host);
}

std::string dataFile(const std::string &relative) {
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const auto installed = exe.parent_path().parent_path() / BINOCLE_DATA_INSTALL_DIR / relative;
    if (!ec && std::filesystem::exists(installed)) return installed.string();
    return (std::filesystem::path(BINOCLE_SOURCE_DIR) / relative).string();
}

Register::Register(Command c) { registry()[c.name] = std::move(c); }

Args::Args(std::vector<std::string> argv, const std::vector<std::string> &flags) {
    for (size_t i = 0; i < argv.size(); ++i) {
        const std::string &a = argv[i];
        if (a.rfind("--", 0) == 0 && a.size() > 2) {
            const auto eq = a.find('=');
            if (eq != std::string::npos) {
                options_.emplace(a.substr(0, eq), a.substr(eq + 1));
            } else if (std::find(flags.begin(), flags.end(), a) != flags.end()) {
                options_.emplace(a, "1");
            } else {
                if (i + 1 >= argv.size()) throw Error("option " + a + " needs a value");
                options_.emplace(a, argv[++i]);
            }
        } else {
            positional_.push_back(a);
        }
    }
}

std::string Args::get(const std::string &name, const std::string &def) const {
    auto it = options_.find(name);
    return it == options_.end() ? def : it->second;
}

std::vector<std::string> Args::all(const std::string &name) const {
    std::vector<std::string> out;
    auto range = options_.equal_range(name);
    for (auto it = range.first; it != range.second; ++it) out.push_back(it->second);
    return out;
}

long long Args::integer(const std::string &name, long long def) const {
    if (!has(name)) return def;
    const std::string v = get(name);
    try {
        size_t used = 0;
        long long x = std::stoll(v, &used);
        if (used == v.size()) return x;
    } catch (const std::logic_error &) {
    }
    throw Error("option " + name + " = '" + v + "': expected an integer");
}

double Args::real(const std::string &name, double def) const {
    if (!has(name)) return def;
    const std::string v = get(name);
    try {
        size_t used = 0;
        double x = std::stod(v, &used);
        if (used == v.size()) return x;
    } catch (const std::logic_error &) {
    }
    throw Error("option " + name + " = '" + v + "': expected a number");
}

} // namespace binocle::cli

namespace {

void usage(std::ostream &os) {
    os << "binocle: stereo camera design and processing framework\n\n"
          "usage: binocle <command> [options]\n\ncommands:\n";
    for (const auto &[name, c] : binocle::cli::commands()) {
        std::string pad(name.size() < 12 ? 12 - name.size() : 1, ' ');
        os << "  " << name << pad << c.summary << "\n";
    }
    os << "\nRun `binocle <command> --help` for a command's options.\n"
          "Plugins are searched in $BINOCLE_PLUGIN_PATH, the install prefix and the build tree.\n";
}

} // namespace

int main(int argc, char **argv) {
    using namespace binocle::cli;
    // Diagnostics go to stderr: stdout carries results (a summary, a listing).
    spdlog::set_default_logger(spdlog::stderr_color_mt("binocle"));
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
        usage(args.empty() ? std::cerr : std::cout);
        return args.empty() ? 2 : 0;
    }
    if (args[0] == "--version") {
        std::cout << "binocle " << BINOCLE_VERSION << " (plugin ABI " << BINOCLE_ABI_VERSION << ", API " << BINOCLE_API_VERSION << ")\n";
        return 0;
    }
    auto it = commands().find(args[0]);
    if (it == commands().end()) {
        std::cerr << "binocle: unknown command '" << args[0] << "'\n\n";
        usage(std::cerr);
        return 2;
    }
    const Command &cmd = it->second;
    std::vector<std::string> rest(args.begin() + 1, args.end());
    for (const auto &a : rest)
        if (a == "--help" || a == "-h") {
            std::cout << cmd.help;
            return 0;
        }
    try {
        return cmd.run(Args(rest, cmd.flags));
    } catch (const std::exception &e) {
        std::cerr << "binocle " << cmd.name << ": error: " << e.what() << "\n";
        return 1;
    }
}
