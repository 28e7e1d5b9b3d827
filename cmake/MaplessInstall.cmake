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

include(${CMAKE_CURRENT_LIST_DIR}/MaplessCrossDepends.cmake)

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
# The libraries io opens when first used (io/lazy_libraries.h: OpenCV's image codecs and video
# I/O, FFmpeg) are not among the command's NEEDED entries, so dpkg-shlibdeps cannot see them:
# their Debian packages are looked up here and named.
set(_mapless_lazy_files)
foreach(_lib opencv_imgcodecs opencv_videoio)
  get_target_property(_file ${_lib} IMPORTED_LOCATION_RELEASE)
  if(NOT _file)
    get_target_property(_file ${_lib} LOCATION)
  endif()
  list(APPEND _mapless_lazy_files ${_file})
endforeach()
foreach(_lib avformat avcodec swscale avutil)
  string(REGEX MATCH "^[0-9]+" _major "${FFMPEG_lib${_lib}_VERSION}")
  list(APPEND _mapless_lazy_files ${FFMPEG_lib${_lib}_LIBDIR}/lib${_lib}.so.${_major})
endforeach()
set(_mapless_lazy_packages)
find_program(MAPLESS_DPKG_QUERY dpkg-query)
foreach(_file IN LISTS _mapless_lazy_files)
  if(CMAKE_CROSSCOMPILING)
    break()
  endif()
  get_filename_component(_real ${_file} REALPATH)
  if(MAPLESS_DPKG_QUERY)
    execute_process(COMMAND ${MAPLESS_DPKG_QUERY} -S ${_real} OUTPUT_VARIABLE _owner
                    ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE)
    string(REGEX MATCH "^[^:,]+" _package "${_owner}")
    if(_package)
      list(APPEND _mapless_lazy_packages ${_package})
    endif()
  endif()
endforeach()
if(CMAKE_CROSSCOMPILING)
  # A cross build (the arm64 preset): the build machine's dpkg-shlibdeps and dpkg-query know only
  # its own architecture's packages. The Depends come instead from the sysroot's index
  # (scripts/sysroot_arm64.sh: soname, package, shlibs dependency), for every NEEDED entry of the
  # packed command and the libraries opened on first use, when cpack runs
  # (cmake/MaplessCrossDepends.cmake).
  mapless_cross_package_depends("${_mapless_lazy_files}")
else()
  list(JOIN _mapless_lazy_packages ", " CPACK_DEBIAN_PACKAGE_DEPENDS)
endif()
set(CPACK_GENERATOR DEB)
include(CPack)
