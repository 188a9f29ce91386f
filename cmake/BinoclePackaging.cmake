# SPDX-License-Identifier: MIT
# Debian packages with CPack (`cpack -G DEB` in the build tree):
#   binocle      the CLI, the plugins, configs and the bash completion (component runtime)
#   binocle-dev  the SDK headers and the CMake package (component sdk)
#   python3-binocle  the `binocle` Python module (component python), when it is built
# Relocatable: the CLI finds its plugins in <exe>/../lib/binocle/plugins and its configs in
# <exe>/../share/binocle, so an extracted package (dpkg -x) runs from wherever it lies.
set(CPACK_GENERATOR "DEB")
set(CPACK_PACKAGE_NAME "binocle")
set(CPACK_PACKAGE_VENDOR "Binocle")
set(CPACK_PACKAGE_CONTACT "Binocle developers <binocle@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Binocular stereo camera design and processing framework")
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime sdk)
if(BINOCLE_BUILD_PYTHON)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_COMPRESSION_TYPE gzip)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME "binocle")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION "science")
# The libraries the CLI and plugins link, as dpkg-shlibdeps finds them.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_SDK_PACKAGE_NAME "binocle-dev")
set(CPACK_DEBIAN_SDK_PACKAGE_SECTION "libdevel")
set(CPACK_DEBIAN_SDK_PACKAGE_DEPENDS "binocle (= ${PROJECT_VERSION}), cmake (>= 3.20)")
set(CPACK_DEBIAN_SDK_PACKAGE_ARCHITECTURE "all")
# The module links the framework statically; it runs the plugins and the helper of the
# binocle package, found from its own folder (../../../.. of dist-packages/binocle).
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME "python3-binocle")
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION "python")
set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "binocle (= ${PROJECT_VERSION}), ${BINOCLE_PYTHON_DEPENDS}")
set(CPACK_COMPONENT_PYTHON_DESCRIPTION "Binocle for Python: rigs, experiments and the plugin list as numpy arrays and dicts")
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "Binocle: the binocle command, its plugins and configurations")
set(CPACK_COMPONENT_SDK_DESCRIPTION "Binocle SDK: plugin ABI headers, C++ helper and CMake package")
include(CPack)
