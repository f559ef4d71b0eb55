# `cmake --install` layout: the CLI, the shipped machine files, and a CMake package so that a
# controller project can find_package(weilgen) and call weilgen_add_model() (examples/).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(WEILGEN_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/weilgen")
set(WEILGEN_INSTALL_MACHINESDIR "${CMAKE_INSTALL_DATADIR}/weilgen/machines")

install(TARGETS weilgen RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
install(DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}/machines/"
  DESTINATION "${WEILGEN_INSTALL_MACHINESDIR}"
  FILES_MATCHING PATTERN "*.yaml" PATTERN "README.md")

# PATH_VARS become prefix-relative paths in the config (relocatable install).
configure_package_config_file(
  "${CMAKE_CURRENT_SOURCE_DIR}/cmake/weilgenConfig.cmake.in"
  "${CMAKE_CURRENT_BINARY_DIR}/weilgenConfig.cmake"
  INSTALL_DESTINATION "${WEILGEN_INSTALL_CMAKEDIR}"
  PATH_VARS CMAKE_INSTALL_BINDIR WEILGEN_INSTALL_MACHINESDIR)
# 0.x: a minor release may change the generated API. ARCH_INDEPENDENT: the package is a
# build-time tool whose headers are portable, so a cross-compiling (e.g. 32-bit ARM) controller
# build must accept the host's install.
write_basic_package_version_file(
  "${CMAKE_CURRENT_BINARY_DIR}/weilgenConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}"
  COMPATIBILITY SameMinorVersion
  ARCH_INDEPENDENT)
install(FILES
  "${CMAKE_CURRENT_BINARY_DIR}/weilgenConfig.cmake"
  "${CMAKE_CURRENT_BINARY_DIR}/weilgenConfigVersion.cmake"
  "${CMAKE_CURRENT_SOURCE_DIR}/cmake/WeilgenAddModel.cmake"
  DESTINATION "${WEILGEN_INSTALL_CMAKEDIR}")
