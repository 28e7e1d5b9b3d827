# The Debian package of a cross build (the arm64 preset, docs/arm64.md): its architecture is the
# target's, and its Depends are read when cpack runs from the packed command's NEEDED entries
# (the cross binutils' readelf) and the libraries opened on first use, each looked up in the
# sysroot's index MAPLESS_SYSROOT/mapless/shlibs.tsv (soname, package, the dependency its shlibs
# file asks for; written by scripts/sysroot_arm64.sh). A soname missing from the index stops cpack
# with its name: a package that depends on less than it needs would install and then not start.

# mapless_cross_package_depends(LAZY_FILES): sets up CPack for the cross package; LAZY_FILES are
# the paths of the libraries io opens on first use (cmake/MaplessInstall.cmake).
function(mapless_cross_package_depends lazy_files)
  set(index "${MAPLESS_SYSROOT}/mapless/shlibs.tsv")
  if(NOT EXISTS "${index}")
    message(FATAL_ERROR "mapless: ${index} is missing: make the sysroot with scripts/sysroot_arm64.sh")
  endif()
  if(CMAKE_SYSTEM_PROCESSOR STREQUAL "aarch64")
    set(arch arm64)
  else()
    message(FATAL_ERROR "mapless: no Debian architecture known for ${CMAKE_SYSTEM_PROCESSOR}")
  endif()
  find_program(MAPLESS_CROSS_READELF NAMES ${CMAKE_LIBRARY_ARCHITECTURE}-readelf REQUIRED)
  set(sonames "")
  foreach(file IN LISTS lazy_files)
    get_filename_component(name "${file}" NAME)
    list(APPEND sonames "${name}")
  endforeach()
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${arch} PARENT_SCOPE)
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS OFF PARENT_SCOPE)
  set(script "${PROJECT_BINARY_DIR}/MaplessCPackCrossDepends.cmake")
  file(WRITE "${script}.in" "# Written by cmake/MaplessCrossDepends.cmake; read by cpack.
set(MAPLESS_READELF \"${MAPLESS_CROSS_READELF}\")
set(MAPLESS_BINARY \"$<TARGET_FILE:mapless>\")
set(MAPLESS_SHLIBS_INDEX \"${index}\")
set(MAPLESS_LAZY_SONAMES \"${sonames}\")
include(\"${CMAKE_CURRENT_FUNCTION_LIST_DIR}/MaplessCPackDepends.cmake\")
")
  file(GENERATE OUTPUT "${script}" INPUT "${script}.in")
  set(CPACK_PROJECT_CONFIG_FILE "${script}" PARENT_SCOPE)
endfunction()
