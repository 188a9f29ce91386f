// SPDX-License-Identifier: MIT
// binocle-plugin-helper: runs one plugin out of Binocle's process (`isolation: process`).
#include "host/isolation.hpp"

#include <cstdlib>
#include <spdlog/spdlog.h>
#include <string>

int main(int argc, char **argv) {
    int fd = -1;
    std::string plugin;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string opt = argv[i];
        if (opt == "--fd") fd = std::atoi(argv[i + 1]);
        else if (opt == "--plugin") plugin = argv[i + 1];
    }
    if (fd < 0 || plugin.empty()) {
        spdlog::error("usage: binocle-plugin-helper --fd N --plugin FILE.so (started by binocle, not by hand)");
        return 2;
    }
    return binocle::serveIsolatedPlugin(fd, plugin);
}
