# SPDX-License-Identifier: MIT
# The plugins_sgm_standalone test (cmake -P): plugins/sgm as a third party would build it,
# from the SDK alone:
#  1. install the SDK component of this build into a fresh prefix
#  2. configure and build a copy of plugins/sgm with that prefix alone (no Binocle source
#     folder on any include path: a framework or plugins/common header would not be found)
#  3. `binocle plugin-check` passes on the .so built there
# Inputs (-D): BUILD_DIR SOURCE_DIR WORK_DIR CLI GENERATOR CXX_COMPILER
cmake_minimum_required(VERSION 3.20)
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR CLI GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "standalone_build.cmake: -D${var}=... is required")
  endif()
endforeach()

function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${what}: exit ${rc}\n${ARGN}\n--- stdout\n${out}\n--- stderr\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
step("installing the SDK component" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --component sdk)
# A copy outside the tree: nothing next to it but itself.
file(COPY "${SOURCE_DIR}/plugins/sgm/" DESTINATION "${WORK_DIR}/sgm")
step("configuring plugins/sgm against the SDK alone" "${CMAKE_COMMAND}" -S "${WORK_DIR}/sgm" -B "${WORK_DIR}/build"
     -G "${GENERATOR}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
step("building plugins/sgm" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
if(NOT EXISTS "${WORK_DIR}/build/binocle_sgm.so")
  message(FATAL_ERROR "the standalone build made no binocle_sgm.so")
endif()
step("binocle plugin-check on the standalone binocle_sgm.so" "${CLI}" plugin-check "${WORK_DIR}/build/binocle_sgm.so")
if(NOT out MATCHES "PASS  compute_in_host_buffers" OR NOT out MATCHES "PASS  determinism")
  message(FATAL_ERROR "plugin-check output lacks the passes expected:\n${out}")
endif()
message(STATUS "plugins/sgm built against ${prefix} alone and checked")
