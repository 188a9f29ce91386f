# SPDX-License-Identifier: MIT
# The sdk_abi test (cmake -P): the SDK's types checked with libabigail against the
# committed baseline (tests/sdk/abi/binocle-abi1.abi).
#  1. build abi/anchor.c (one function reaching every SDK type) with -g against the SDK,
#     abidw it, abidiff it against the baseline: it must be compatible
#  2. prove the check can fail: copies of the SDK headers with one member appended at the
#     end of the matcher table (allowed), inserted in its middle (refused), and with a
#     field's type changed (refused)
# Compatible means: no difference, or only members appended at the end of structs (the
# rule of common.h: tables grow by appending; the host reads what fits in struct_size).
# Regenerate the baseline after an intended ABI version bump with -DREGENERATE=ON.
# Inputs (-D): SDK_INCLUDE ANCHOR BASELINE WORK_DIR CC ABIDW ABIDIFF [REGENERATE]
cmake_minimum_required(VERSION 3.20)

foreach(var SDK_INCLUDE ANCHOR BASELINE WORK_DIR CC ABIDW ABIDIFF)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "abi_check.cmake: -D${var}=... is required")
  endif()
endforeach()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# Builds the anchor against the headers in `include` and writes its ABI to `out`.
function(abi_of include out)
  get_filename_component(name "${out}" NAME_WE)
  # Compiled from its own folder by file name: no checkout path lands in the debug info.
  get_filename_component(anchor_dir "${ANCHOR}" DIRECTORY)
  get_filename_component(anchor_file "${ANCHOR}" NAME)
  execute_process(COMMAND "${CC}" -g -O0 -shared -fPIC -fvisibility=hidden -I "${include}" "${anchor_file}"
                          -o "${WORK_DIR}/${name}.so"
                  WORKING_DIRECTORY "${anchor_dir}" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "building the ABI anchor against ${include} failed:\n${err}")
  endif()
  # No build paths in the XML: the baseline is the same from any checkout.
  execute_process(COMMAND "${ABIDW}" --no-corpus-path --no-comp-dir-path --no-show-locs "${WORK_DIR}/${name}.so"
                  OUTPUT_FILE "${out}" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc STREQUAL "0")
    message(FATAL_ERROR "abidw ${WORK_DIR}/${name}.so failed (${rc}):\n${err}")
  endif()
endfunction()

# Sets `verdict` to "" when `new` is compatible with `old`, else to the reason and report.
function(compare old new)
  execute_process(COMMAND "${ABIDIFF}" --leaf-changes-only --no-show-locs "${old}" "${new}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE report ERROR_VARIABLE err)
  if(rc STREQUAL "0")
    set(verdict "" PARENT_SCOPE)
    return()
  endif()
  if(NOT report)
    set(verdict "abidiff failed (${rc}): ${err}" PARENT_SCOPE)
    return()
  endif()
  # Anything but a size growth with members inserted at or past the old end is a break.
  string(REPLACE "\n" ";" lines "${report}")
  set(old_bits "")
  set(problem "")
  foreach(line IN LISTS lines)
    if(line STREQUAL "" OR line MATCHES "^(Leaf changes summary|Changed leaf types summary|Removed/Changed/Added variables summary: 0 Removed, 0 Changed)"
       OR line MATCHES "^Removed/Changed/Added functions summary: 0 Removed, 0 Changed, 0 Added"
       OR line MATCHES "^'struct [A-Za-z0-9_]+' changed:$" OR line MATCHES "^  [0-9]+ data member insertions?:$")
      continue()
    elseif(line MATCHES "^  type size changed from ([0-9]+) to ([0-9]+) \\(in bits\\)$")
      set(old_bits "${CMAKE_MATCH_1}")
      if(CMAKE_MATCH_2 LESS CMAKE_MATCH_1)
        set(problem "a struct shrank: ${line}")
      endif()
    elseif(line MATCHES "^    '.*', at offset ([0-9]+) \\(in bits\\)$")
      if(old_bits STREQUAL "" OR CMAKE_MATCH_1 LESS old_bits)
        set(problem "a member was inserted before the end of its struct: ${line}")
      endif()
    else()
      set(problem "an incompatible change: ${line}")
    endif()
    if(problem)
      break()
    endif()
  endforeach()
  if(problem)
    set(verdict "${problem}\n--- abidiff report\n${report}" PARENT_SCOPE)
  else()
    set(verdict "" PARENT_SCOPE)
  endif()
endfunction()

# Copies the SDK headers to `dir`, replacing `from` by `to` in binocle/abi/<file>.
function(variant dir file from to)
  file(COPY "${SDK_INCLUDE}/binocle" DESTINATION "${dir}")
  file(READ "${dir}/binocle/abi/${file}" text)
  string(FIND "${text}" "${from}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "abi_check.cmake: '${from}' not found in ${file}; update the variants of this test")
  endif()
  string(REPLACE "${from}" "${to}" text "${text}")
  file(WRITE "${dir}/binocle/abi/${file}" "${text}")
endfunction()

abi_of("${SDK_INCLUDE}" "${WORK_DIR}/current.abi")
if(REGENERATE)
  file(COPY_FILE "${WORK_DIR}/current.abi" "${BASELINE}")
  message(STATUS "wrote ${BASELINE}")
  return()
endif()

# 1. Today's SDK against the baseline.
compare("${BASELINE}" "${WORK_DIR}/current.abi")
if(verdict)
  message(FATAL_ERROR "the SDK's types changed incompatibly with the ABI ${BASELINE} records: ${verdict}\n"
                      "Append new entries at the end of a table instead, or bump BINOCLE_ABI_VERSION and regenerate the "
                      "baseline (cmake -DREGENERATE=ON ... -P abi_check.cmake).")
endif()

# 2. The check tells an append from a break.
set(end_of_matcher "                             int32_t *count);\n} binocle_matcher_api;")
variant("${WORK_DIR}/appended" matcher.h "${end_of_matcher}"
        "                             int32_t *count);\n    void *appended;\n} binocle_matcher_api;")
abi_of("${WORK_DIR}/appended" "${WORK_DIR}/appended.abi")
compare("${BASELINE}" "${WORK_DIR}/appended.abi")
if(verdict)
  message(FATAL_ERROR "an entry appended at the end of the matcher table was refused: ${verdict}")
endif()

variant("${WORK_DIR}/inserted" matcher.h "    binocle_result (*compute)(" "    void *inserted;\n    binocle_result (*compute)(")
abi_of("${WORK_DIR}/inserted" "${WORK_DIR}/inserted.abi")
compare("${BASELINE}" "${WORK_DIR}/inserted.abi")
if(NOT verdict MATCHES "inserted before the end|incompatible change")
  message(FATAL_ERROR "an entry inserted in the middle of the matcher table was not caught (verdict: '${verdict}')")
endif()

variant("${WORK_DIR}/retyped" common.h "    int32_t stride_bytes;" "    int64_t stride_bytes;")
abi_of("${WORK_DIR}/retyped" "${WORK_DIR}/retyped.abi")
compare("${BASELINE}" "${WORK_DIR}/retyped.abi")
if(NOT verdict MATCHES "incompatible change")
  message(FATAL_ERROR "a field whose type changed (binocle_image::stride_bytes) was not caught (verdict: '${verdict}')")
endif()
message(STATUS "SDK ABI compatible with ${BASELINE}; an inserted entry and a changed field type are caught")
