# SPDX-License-Identifier: MIT
# Sourced by scripts/build.sh and scripts/sanitize.sh: how both trees use ccache.
# Sets $launcher to the CMake arguments that put ccache in front of the compilers
# (empty when ccache is not installed).
#
# Paths inside the checkout are hashed relative to it, so that clones in other folders
# (CI's fresh clone) share the cache; files that use a precompiled header (the
# framework's, the tests') are cacheable only when ccache may ignore the header's
# timestamps and predefined macros. The settings travel in the launcher itself (through
# env), so that `cmake --build` run without these scripts caches the same way.
#
# Depend mode: on a miss, ccache takes the headers a file read from the compiler's own
# dependency file (-MD, which CMake's Ninja rules pass) instead of running the
# preprocessor first. That run cost a second of CPU per file on a miss (measured: the
# framework's log.cpp 5.5 s of CPU without ccache, 6.5 s through ccache on an empty
# cache, 5.1 s in depend mode), which is every file of a fresh clone with an empty cache.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
export CCACHE_SLOPPINESS="${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}"
export CCACHE_DEPEND="${CCACHE_DEPEND:-1}"
launcher=()
if command -v ccache >/dev/null 2>&1; then
  ccache_launcher="$(command -v env);CCACHE_BASEDIR=$CCACHE_BASEDIR;CCACHE_NOHASHDIR=$CCACHE_NOHASHDIR;CCACHE_SLOPPINESS=$CCACHE_SLOPPINESS;CCACHE_DEPEND=$CCACHE_DEPEND;ccache"
  launcher=("-DCMAKE_C_COMPILER_LAUNCHER=$ccache_launcher" "-DCMAKE_CXX_COMPILER_LAUNCHER=$ccache_launcher")
fi
