# SPDX-License-Identifier: MIT
# binocle_add_python_plugin(<name> MODULE <file.py> [OUTPUT_DIRECTORY <dir>] [NO_INSTALL])
#
# Makes a Binocle plugin of a Python class: binocle_<name>.so, a copy of the Python
# bridge (a plugin that embeds CPython and learns <name> from its own file name), and
# binocle_<name>.py, a copy of <file.py>, side by side. The host sees an ordinary
# plugin named <name>; nothing is compiled. Rules of the class: sdk/README.md
# ("Plugins in Python"). Installed with the SDK, so that a plugin author outside this
# tree uses the very same function (the bridge then comes from the SDK's install).
#   MODULE            the Python file holding the class (module attribute binocle_plugin)
#   OUTPUT_DIRECTORY  where the pair goes (default: the build's plugin folder when there
#                     is one, else the current build folder)
#   NO_INSTALL        no install rule (test fixtures); otherwise both files install
#                     into BINOCLE_PLUGIN_INSTALL_DIR, beside the C plugins
function(binocle_add_python_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "MODULE;OUTPUT_DIRECTORY" "" ${ARGN})
  if(NOT name MATCHES "^[a-z0-9_]+$")
    message(FATAL_ERROR "binocle_add_python_plugin(${name}): a plugin name is [a-z0-9_]+ (it is a YAML value and a file name)")
  endif()
  if(NOT ARG_MODULE)
    message(FATAL_ERROR "binocle_add_python_plugin(${name}): MODULE <file.py> is required")
  endif()
  get_filename_component(module "${ARG_MODULE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(TARGET binocle_plugin_python_bridge)
    set(bridge "$<TARGET_FILE:binocle_plugin_python_bridge>")
    set(bridge_dependency binocle_plugin_python_bridge)
  elseif(DEFINED BINOCLE_PYTHON_BRIDGE AND EXISTS "${BINOCLE_PYTHON_BRIDGE}")
    set(bridge "${BINOCLE_PYTHON_BRIDGE}")
    set(bridge_dependency "${BINOCLE_PYTHON_BRIDGE}")
  else()
    message(FATAL_ERROR "binocle_add_python_plugin(${name}): no Python bridge (Binocle was built without "
      "Python's development files: Debian's libpython3-dev)")
  endif()
  if(ARG_OUTPUT_DIRECTORY)
    set(out "${ARG_OUTPUT_DIRECTORY}")
  elseif(DEFINED BINOCLE_BUILD_PLUGIN_DIR)
    set(out "${BINOCLE_BUILD_PLUGIN_DIR}")
  else()
    set(out "${CMAKE_CURRENT_BINARY_DIR}")
  endif()
  set(so "${out}/binocle_${name}.so")
  set(py "${out}/binocle_${name}.py")
  add_custom_command(OUTPUT "${so}" "${py}"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${out}"
    COMMAND "${CMAKE_COMMAND}" -E copy "${bridge}" "${so}"
    COMMAND "${CMAKE_COMMAND}" -E copy "${module}" "${py}"
    DEPENDS ${bridge_dependency} "${module}"
    COMMENT "Python plugin ${name}: binocle_${name}.so (the bridge) and binocle_${name}.py"
    VERBATIM)
  add_custom_target(binocle_plugin_${name} ALL DEPENDS "${so}" "${py}")
  if(TARGET binocle_all_plugins)
    add_dependencies(binocle_all_plugins binocle_plugin_${name})
  endif()
  if(NOT ARG_NO_INSTALL AND DEFINED BINOCLE_PLUGIN_INSTALL_DIR)
    if(DEFINED BINOCLE_PLUGIN_INSTALL_COMPONENT)
      install(PROGRAMS "${so}" DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}" COMPONENT ${BINOCLE_PLUGIN_INSTALL_COMPONENT})
      install(FILES "${py}" DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}" COMPONENT ${BINOCLE_PLUGIN_INSTALL_COMPONENT})
    else()
      install(PROGRAMS "${so}" DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}")
      install(FILES "${py}" DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}")
    endif()
    set_property(GLOBAL APPEND PROPERTY BINOCLE_PLUGINS ${name})
  endif()
endfunction()
