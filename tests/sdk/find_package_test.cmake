# SPDX-License-Identifier: MIT
# The sdk_find_package test (cmake -P): a third-party plugin author's whole path.
#  1. install the SDK component of this build into a fresh prefix; only public files land
#  2. configure a copy of find_package_test/ with CMAKE_PREFIX_PATH = that prefix alone,
#     and check it used the installed package, never the source tree
#  3. build the plugin (it exports binocle_plugin_init alone) and install it (into the
#     SDK's BINOCLE_PLUGIN_DIR)
#  4. the built `binocle` accepts it with --load and from the installed plugin folder
#  5. `binocle run` uses it in a rig fed by the mock_source test fixture
# Inputs (-D): BUILD_DIR SOURCE_DIR PROJECT_DIR WORK_DIR CLI TEST_PLUGIN_DIR GENERATOR CXX_COMPILER
cmake_minimum_required(VERSION 3.20)

foreach(var BUILD_DIR SOURCE_DIR PROJECT_DIR WORK_DIR CLI TEST_PLUGIN_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "find_package_test.cmake: -D${var}=... is required")
  endif()
endforeach()

# Runs a command; fails the test with its output unless it exits 0. Output in step_output.
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "${what} failed (${rc}):\n${ARGN}\n--- stdout\n${out}\n--- stderr\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
  set(step_errors "${err}" PARENT_SCOPE)
endfunction()

function(expect_match what regex text)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "${what}: expected to match '${regex}' in:\n${text}")
  endif()
endfunction()

set(prefix "${WORK_DIR}/prefix")
set(project "${WORK_DIR}/project")
set(build "${WORK_DIR}/build")
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# 1. The SDK alone, and nothing internal in it.
run_step("installing the SDK component" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}" --component sdk)
file(GLOB_RECURSE installed RELATIVE "${prefix}" "${prefix}/*")
message(STATUS "installed SDK: ${installed}")
foreach(required include/binocle/abi.h include/binocle/abi/common.h include/binocle/plugin.hpp)
  if(NOT EXISTS "${prefix}/${required}")
    message(FATAL_ERROR "the SDK install lacks ${required} (installed: ${installed})")
  endif()
endforeach()
foreach(file IN LISTS installed)
  if(NOT file MATCHES "^include/binocle/(abi\\.h|abi/[a-z_]+\\.h|plugin\\.hpp|error\\.hpp|recording\\.hpp|text\\.hpp|mcap\\.hpp|ros2_messages\\.hpp|settings\\.hpp|numbers\\.hpp)$"
     AND NOT file MATCHES "/cmake/Binocle/[A-Za-z_-]+\\.cmake$" AND NOT file MATCHES "^lib[^/]*/libbinocle_mcap\\.a$"
     # the Python bridge, copied per Python plugin by binocle_add_python_plugin
     AND NOT file MATCHES "^lib[^/]*/binocle/python/binocle_python_bridge\\.so$")
    message(FATAL_ERROR "the SDK install holds ${file}: only the public headers, the CMake package, the MCAP library and the Python bridge belong to it")
  endif()
endforeach()

# 2. Configure a copy of the project, so that no path leads back into the source tree.
file(COPY "${PROJECT_DIR}/" DESTINATION "${project}")
run_step("configuring the out-of-tree plugin" "${CMAKE_COMMAND}" -S "${project}" -B "${build}" -G "${GENERATOR}"
  "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_PREFIX_PATH=${prefix}" -DCMAKE_BUILD_TYPE=Release
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)
file(STRINGS "${build}/CMakeCache.txt" binocle_dir REGEX "^Binocle_DIR:")
expect_match("Binocle_DIR of the out-of-tree build" "^Binocle_DIR:PATH=${prefix}/" "${binocle_dir}")
file(READ "${build}/compile_commands.json" commands)
expect_match("include path of the out-of-tree build" "${prefix}/include" "${commands}")
foreach(internal sdk framework cmake)
  string(FIND "${commands}" "${SOURCE_DIR}/${internal}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the out-of-tree build reaches into the source tree (${SOURCE_DIR}/${internal}):\n${commands}")
  endif()
endforeach()

# 3. Build, and install into the SDK's plugin folder.
run_step("building the out-of-tree plugin" "${CMAKE_COMMAND}" --build "${build}")
file(GLOB_RECURSE built "${build}/binocle_external_matcher.so")
if(NOT built)
  message(FATAL_ERROR "no binocle_external_matcher.so in ${build}")
endif()
# binocle_add_plugin() from the package exports the init symbol and nothing else.
find_program(NM nm)
if(NM)
  run_step("listing the plugin's exported symbols" "${NM}" -D --defined-only "${built}")
  string(REGEX MATCHALL "[^\n]* [TtWwVvDdBbRrUui] [^\n]+" symbols "${step_output}")
  string(REGEX REPLACE "[^;]* [A-Za-z] " "" names "${symbols}")
  if(NOT names STREQUAL "binocle_plugin_init")
    message(FATAL_ERROR "the out-of-tree plugin exports more than binocle_plugin_init: ${names}")
  endif()
endif()
run_step("installing the out-of-tree plugin" "${CMAKE_COMMAND}" --install "${build}")
file(GLOB_RECURSE plugin_installed "${prefix}/*/binocle_external_matcher.so")
if(NOT plugin_installed)
  message(FATAL_ERROR "installing the out-of-tree plugin did not put it into the SDK's BINOCLE_PLUGIN_DIR under ${prefix}")
endif()
get_filename_component(plugin_dir "${plugin_installed}" DIRECTORY)

# 4. The host accepts it: named on the command line, and found in the installed folder.
set(listed "\n  external_matcher *matcher +1\\.2\\.3 +ABI 1 API 1 +built out of tree against the installed SDK")
run_step("binocle plugins --load" "${CMAKE_COMMAND}" -E env --unset=BINOCLE_PLUGIN_PATH "${CLI}" plugins --load "${built}")
expect_match("binocle plugins --load ${built}" "${listed}" "${step_output}")
run_step("binocle plugins (installed folder)" "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${plugin_dir}" "${CLI}" plugins --verbose)
expect_match("binocle plugins with BINOCLE_PLUGIN_PATH=${plugin_dir}" "${listed}\n +file: ${plugin_installed}\n +disparity_px +6 px" "${step_output}")
if(step_output MATCHES "refused:[^\n]*\n[^\n]*external_matcher")
  message(FATAL_ERROR "binocle refused the out-of-tree plugin:\n${step_output}")
endif()

# 5. And runs it.
file(WRITE "${WORK_DIR}/rig.yaml" "name: external
source:
  plugin: mock_source
  frames: 2
matcher:
  plugin: external_matcher
  disparity_px: 5
outputs:
  disparity_png: false
  disparity_color: false
  cloud_ply: false
")
run_step("binocle run with the out-of-tree matcher" "${CMAKE_COMMAND}" -E env "BINOCLE_PLUGIN_PATH=${plugin_dir}:${TEST_PLUGIN_DIR}"
  "${CLI}" run "${WORK_DIR}/rig.yaml" --quiet)
expect_match("summary of binocle run" "\"matcher\": *\"external_matcher\"" "${step_output}")
expect_match("summary of binocle run" "\"frame_count\": *2[,\n ]" "${step_output}")
expect_match("summary of binocle run" "\"status\": *\"ok\"" "${step_output}")
message(STATUS "out-of-tree plugin built against ${prefix}, loaded and run by ${CLI}")
