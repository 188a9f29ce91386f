# SPDX-License-Identifier: MIT
# The sdk_example_plugin test (cmake -P): examples/census_matcher, a matcher with keys of
# its own, as its author would take it from the SDK README alone:
#  1. install the SDK component of this build into a fresh prefix
#  2. configure and build a copy of the example with that prefix alone
#  3. `binocle plugin-check census` passes
#  4. a rig written for bm runs with its whole matcher block swapped on the command line
#     (--set 'matcher={plugin: census, ...}'); swapping `plugin:` alone fails on bm's keys
# Inputs (-D): BUILD_DIR EXAMPLE_DIR WORK_DIR CLI TEST_PLUGIN_DIR BUILD_PLUGIN_DIR GENERATOR CXX_COMPILER
cmake_minimum_required(VERSION 3.20)
foreach(var BUILD_DIR EXAMPLE_DIR WORK_DIR CLI TEST_PLUGIN_DIR BUILD_PLUGIN_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "example_plugin.cmake: -D${var}=... is required")
  endif()
endforeach()

function(step what expect_rc)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if((expect_rc STREQUAL "0" AND NOT rc STREQUAL "0") OR (expect_rc STREQUAL "fail" AND rc STREQUAL "0"))
    message(FATAL_ERROR "${what}: exit ${rc}, expected ${expect_rc}\n${ARGN}\n--- stdout\n${out}\n--- stderr\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()

function(expect what regex text)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "${what}: expected to match '${regex}' in:\n${text}")
  endif()
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
step("installing the SDK component" 0 "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --component sdk)
file(COPY "${EXAMPLE_DIR}/" DESTINATION "${WORK_DIR}/census")
step("configuring the example against the SDK alone" 0 "${CMAKE_COMMAND}" -S "${WORK_DIR}/census" -B "${WORK_DIR}/build"
     -G "${GENERATOR}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF)
step("building the example" 0 "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
if(NOT EXISTS "${WORK_DIR}/build/binocle_census.so")
  message(FATAL_ERROR "the example did not build binocle_census.so")
endif()

set(path "${WORK_DIR}/build:${TEST_PLUGIN_DIR}:${BUILD_PLUGIN_DIR}")
step("binocle plugin-check census" 0 "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${path}" "${CLI}" plugin-check census
     --junit "${WORK_DIR}/census.xml")
expect("plugin-check census" "PASS  compute_in_host_buffers" "${out}")
expect("plugin-check census" "PASS  determinism" "${out}")

file(WRITE "${WORK_DIR}/rig.yaml" "name: swap
source:
  plugin: mock_source
  frames: 2
  width: 96
  height: 64
matcher:
  plugin: bm
  block_size: 9
  num_disparities: 16
outputs:
  disparity_png: false
  disparity_color: false
  cloud_ply: false
")
step("swapping plugin: alone" fail "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${path}" "${CLI}" run "${WORK_DIR}/rig.yaml"
     --quiet --set matcher.plugin=census)
expect("swapping plugin: alone" "unknown key '(block_size|num_disparities)' for plugin 'census'" "${err}")
step("swapping the whole matcher block" 0 "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${path}" "${CLI}" run "${WORK_DIR}/rig.yaml"
     --quiet "--set" "matcher={plugin: census, window_px: 5, max_disparity_px: 16}")
expect("summary of the swapped rig" "\"matcher\": *\"census\"" "${out}")
expect("summary of the swapped rig" "\"status\": *\"ok\"" "${out}")
message(STATUS "census built against ${prefix} alone, checked and run in a rig")
