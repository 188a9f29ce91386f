# SPDX-License-Identifier: MIT
# The no_build_path test (cmake -P): the built `binocle` and its helper hold no path of
# the build tree's plugin folder, so an installed copy never searches a folder that may
# be gone or that anyone could create.
# Inputs (-D): CLI HELPER BUILD_PLUGIN_DIR
cmake_minimum_required(VERSION 3.20)
foreach(binary "${CLI}" "${HELPER}")
  file(STRINGS "${binary}" hits REGEX "${BUILD_PLUGIN_DIR}")
  if(hits)
    message(FATAL_ERROR "${binary} holds the build-tree path ${BUILD_PLUGIN_DIR}: ${hits}")
  endif()
endforeach()
message(STATUS "no build-tree plugin path in ${CLI} and ${HELPER}")
