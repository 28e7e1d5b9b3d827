# `cmake --install`: the `mapless` command, every module's static library and headers, and a CMake
# package, so that another project can `find_package(mapless)` and link `mapless::control`,
# `mapless::navigation`, ... (the same names as inside this tree). The middleware adapters (ros1,
# ros2) are built into the command and not installed as libraries. `cpack -G DEB` packs the same
# tree as a Debian package whose Depends come from the binaries' shared libraries.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_property(_modules GLOBAL PROPERTY MAPLESS_INSTALLED_MODULES)
set(_targets "")
foreach(m IN LISTS _modules)
  list(APPEND _targets mapless_${m})
endforeach()
install(TARGETS ${_targets} EXPORT maplessTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS mapless RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(m IN LISTS _modules)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/mapless/${m}/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mapless/${m}
          FILES_MATCHING PATTERN "*.h" PATTERN "*_test.h" EXCLUDE)
endforeach()
install(EXPORT maplessTargets NAMESPACE mapless::
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mapless)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/maplessConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/maplessConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mapless)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/maplessConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/maplessConfig.cmake
              ${PROJECT_BINARY_DIR}/maplessConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mapless)
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

# The Debian package: Depends from dpkg-shlibdeps (the runtime packages of every shared library
# the command links), installed under /usr.
set(CPACK_PACKAGE_NAME mapless)
set(CPACK_PACKAGE_VENDOR "mapless")
set(CPACK_PACKAGE_CONTACT "mapless developers <mapless@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Robot navigation from one uncalibrated camera, without a metric map")
set(CPACK_PACKAGE_DESCRIPTION
    "Visual teach and repeat with funnel lanes, visual potential navigation and homing, and
appearance route following with incremental PCA: the mapless command, its libraries, headers
and CMake package.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_GENERATOR DEB)
include(CPack)
