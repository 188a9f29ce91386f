# SPDX-License-Identifier: MIT
# The python_matcher.sdk test (cmake -P): examples/python_matcher as a third party takes
# it, with the SDK component of this build installed alone into a fresh prefix: the
# project configures and builds (nothing compiled: the SDK's bridge is copied) and
# `binocle plugin-check numpy_sad` passes on what it built.
# Inputs (-D): BUILD_DIR EXAMPLE_DIR WORK_DIR CLI GENERATOR
foreach(var BUILD_DIR EXAMPLE_DIR WORK_DIR CLI GENERATOR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "sdk_python_plugin.cmake: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${what}: exit ${rc}\n--- stdout\n${out}\n--- stderr\n${err}")
  endif()
  message(STATUS "${what}: ok")
  set(out "${out}" PARENT_SCOPE)
endfunction()
step("installing the SDK component" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --component sdk)
step("configuring the example against the SDK alone" "${CMAKE_COMMAND}" -S "${EXAMPLE_DIR}" -B "${WORK_DIR}/build"
     -G "${GENERATOR}" "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
step("building the example" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
step("plugin-check on what it built" "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${WORK_DIR}/build" "${CLI}" plugin-check numpy_sad)
if(NOT out MATCHES "9 passed, 0 failed")
  message(FATAL_ERROR "plugin-check did not pass every case:\n${out}")
endif()
