// SPDX-License-Identifier: MIT
// A file of the source tree compiled into the binary (cmake/EmbedFiles.cmake): the
// viewer's page and the report's template need nothing on disk at run time.
#pragma once

#include <cstddef>
#include <string>

namespace binocle {

struct EmbeddedFile {
    const char *name; // path relative to the folder it was embedded from
    const unsigned char *data;
    size_t size;
    std::string text() const { return std::string(reinterpret_cast<const char *>(data), size); }
};

} // namespace binocle
