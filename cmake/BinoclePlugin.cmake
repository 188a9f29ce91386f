# SPDX-License-Identifier: MIT
# binocle_add_plugin(<name> SOURCES <files...> [LIBRARIES <targets...>]
#                    [OUTPUT_DIRECTORY <dir>] [NO_INSTALL])
#
# Builds a Binocle plugin: a MODULE library with hidden visibility that exports only
# its init symbols (binocle_plugin_init, and binocle_plugin_init_error when the plugin
# defines it; enforced by a linker version script), named
# binocle_<name>.so. <name> must be the name the plugin declares in its table
# ([a-z0-9_]+): the host finds a rig's plugin by that file name alone, and refuses a
# file whose name differs. Installed with the SDK, so that a plugin built outside this
# tree uses the very same function.
#   SOURCES           the plugin's source files
#   LIBRARIES         libraries to link, privately (OpenCV, your own code ...)
#   OUTPUT_DIRECTORY  where the built .so goes (default: the build's plugin folder when
#                     there is one, else CMake's default)
#   NO_INSTALL        do not install it (test fixtures); otherwise it installs into
#                     BINOCLE_PLUGIN_INSTALL_DIR (the SDK's BINOCLE_PLUGIN_DIR unless the
#                     project set its own), where the installed `binocle` finds it
# Plugins that install are listed in the global property BINOCLE_PLUGINS (plugin-check
# runs against each in CI).
function(binocle_add_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "OUTPUT_DIRECTORY" "SOURCES;LIBRARIES" ${ARGN})
  if(NOT name MATCHES "^[a-z0-9_]+$")
    message(FATAL_ERROR "binocle_add_plugin(${name}): a plugin name is [a-z0-9_]+ (it is a YAML value and a file name)")
  endif()
  set(target binocle_plugin_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  if(TARGET Binocle::sdk)
    target_link_libraries(${target} PRIVATE Binocle::sdk)
  endif()
  target_link_libraries(${target} PRIVATE ${ARG_LIBRARIES})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    OUTPUT_NAME "binocle_${name}"
    CXX_VISIBILITY_PRESET hidden
    C_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  # Export the init symbols only (binocle_plugin_init, and the optional
  # binocle_plugin_init_error of binocle/abi/init_error.h: a pattern, so that a plugin
  # without it links with any linker): a version script also hides the weak template
  # instantiations (std::string, ...) that visibility flags alone leave exported. Written
  # when its text changes only.
  set(version_script "${CMAKE_BINARY_DIR}/binocle_plugin.map")
  file(CONFIGURE OUTPUT "${version_script}" CONTENT "{ global: binocle_plugin_init*; local: *; };\n")
  if(NOT APPLE AND NOT WIN32)
    target_link_options(${target} PRIVATE "LINKER:--version-script=${version_script}")
    set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS "${version_script}")
  endif()
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${ARG_OUTPUT_DIRECTORY}")
  elseif(DEFINED BINOCLE_BUILD_PLUGIN_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${BINOCLE_BUILD_PLUGIN_DIR}")
  endif()
  if(TARGET binocle_all_plugins)
    add_dependencies(binocle_all_plugins ${target})
  endif()
  if(NOT ARG_NO_INSTALL AND DEFINED BINOCLE_PLUGIN_INSTALL_DIR)
    if(DEFINED BINOCLE_PLUGIN_INSTALL_COMPONENT)
      install(TARGETS ${target} LIBRARY DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}" COMPONENT ${BINOCLE_PLUGIN_INSTALL_COMPONENT})
    else()
      install(TARGETS ${target} LIBRARY DESTINATION "${BINOCLE_PLUGIN_INSTALL_DIR}")
    endif()
  endif()
  if(NOT ARG_NO_INSTALL)
    set_property(GLOBAL APPEND PROPERTY BINOCLE_PLUGINS ${name})
  endif()
endfunction()
