# Helpers shared by every target of the project.

# Warnings as errors and the arithmetic's flags on the project's own targets only (never in global
# flags).
function(mapless_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wold-style-cast -Wcast-align -Wunused -Woverloaded-virtual
                                           -Wnull-dereference -Wformat=2 -Werror)
  # GCC 12 for aarch64 reports a null dereference inside libstdc++'s std::string copy (a vector
  # of objects with names copied, eval/suite.cc) that x86-64's GCC 12 does not: kept a warning
  # there (docs/arm64.md).
  if(CMAKE_CROSSCOMPILING AND CMAKE_SYSTEM_PROCESSOR STREQUAL "aarch64")
    target_compile_options(${target} PRIVATE -Wno-error=null-dereference)
  endif()
  # No contraction of a*b+c into one fused multiply-add: every product and sum rounds on its own,
  # on every CPU. GCC fuses by default in C++ where the target has FMA (always on aarch64, and on
  # x86-64 with -march=native), which moves the last bit of a float and then, through a
  # comparison, a decision: with this flag an arm64 build makes the decisions of x86-64's
  # (tests/arm64/same_decisions.sh) and the SIMD kernels equal their portable loops
  # (docs/arm64.md).
  target_compile_options(${target} PRIVATE -ffp-contract=off)
  if(MAPLESS_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

# The sanitizer build compiles a target's own code at -O0 when that code is glue (the command
# line, the tests, and the edge libraries that move bytes or drive the methods rather than compute:
# files, routes, recordings, reports, the evaluation drivers, the run layer, the fleet link, the
# live view, the bench): the libraries where the time goes stay at the preset's -O1. This saves
# 40-60% of those files' compile time (templates: CLI11, nlohmann/json, GoogleTest, asio and
# websocketpp, cppzmq), and command 2 must stay under 20 minutes on 2 cores (docs/ci.md). ASan
# checks as much at -O0: only optimisations ever remove a check.
function(mapless_glue_code target)
  if(MAPLESS_SANITIZE)
    target_compile_options(${target} PRIVATE -O0)
  endif()
endfunction()

# mapless_library(NAME name SRCS ... PUBLIC_DEPS ... PRIVATE_DEPS ... [NO_INSTALL] [GLUE])
# One static library per module folder: mapless_<name>, alias mapless::<name>. Installed (with
# `cmake --install`) and exported as mapless::<name> in the CMake package (cmake/MaplessInstall.cmake)
# unless NO_INSTALL: the middleware adapters stay inside the `mapless` command. GLUE: an edge
# library, compiled at -O0 under the sanitizers (mapless_glue_code).
function(mapless_library)
  cmake_parse_arguments(ARG "NO_INSTALL;GLUE" "NAME" "SRCS;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target mapless_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SRCS})
  add_library(mapless::${ARG_NAME} ALIAS ${target})
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                              $<INSTALL_INTERFACE:include>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  mapless_target_warnings(${target})
  if(ARG_GLUE)
    mapless_glue_code(${target})
  endif()
  if(NOT ARG_NO_INSTALL)
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
    set_property(GLOBAL APPEND PROPERTY MAPLESS_INSTALLED_MODULES ${ARG_NAME})
  endif()
endfunction()

# The compile flags of every GoogleTest binary's own code (and of mapless_test_main, whose
# precompiled header they reuse: a precompiled header needs the same optimisation level).
function(mapless_test_flags target)
  mapless_target_warnings(${target})
  mapless_glue_code(${target})
  # In the release build a test's own code is glue too (assertions, fixtures; the work is in the
  # libraries, at -O3): -O1 compiles it in 60% of the time (issue 39, docs/ci.md).
  if(NOT MAPLESS_SANITIZE AND CMAKE_BUILD_TYPE STREQUAL "Release")
    target_compile_options(${target} PRIVATE -O1)
  endif()
endfunction()

# One precompiled header of the system headers most tests include (GoogleTest, OpenCV, Eigen,
# nlohmann/json, the standard library), built once with mapless_test_main and reused by every test
# binary: each of them parsed these headers again, about 3 s of CPU a binary under the sanitizers
# and 2 s in the release build (docs/ci.md). MAPLESS_TEST_PCH=OFF turns it off (the dev preset
# does, so that a test file that does not include what it uses fails to compile there).
option(MAPLESS_TEST_PCH "Reuse one precompiled header in every GoogleTest binary" ON)
function(mapless_test_precompiled_header)
  if(MAPLESS_TEST_PCH)
    target_precompile_headers(mapless_test_main PRIVATE
      <gtest/gtest.h> <opencv2/core.hpp> <opencv2/imgproc.hpp> <Eigen/Core>
      <nlohmann/json.hpp> <algorithm> <chrono> <cmath> <filesystem> <fstream> <functional>
      <map> <memory> <sstream> <string> <thread> <vector>)
  endif()
endfunction()

# mapless_test(NAME name SRCS ... DEPS ... [SANITIZE_ENV VAR=VALUE ...] [COST N]): one GoogleTest
# binary, tests discovered by ctest. SANITIZE_ENV: extra environment for its tests in the sanitizer
# build. COST: ctest starts tests of higher cost first (closed loops: a clean clone has no timing
# history, and a long test started last would end the run alone on one core).
function(mapless_test)
  if(NOT MAPLESS_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "MIDDLEWARE" "NAME;COST" "SRCS;DEPS;SANITIZE_ENV" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} GTest::gtest mapless_test_main)
  target_compile_definitions(${ARG_NAME} PRIVATE
    MAPLESS_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  mapless_test_flags(${ARG_NAME})
  if(MAPLESS_TEST_PCH)
    target_precompile_headers(${ARG_NAME} REUSE_FROM mapless_test_main)
  endif()
  # Label `unit`: a GoogleTest case (scripts/test.sh runs these under the sanitizers, and in the
  # release build only those in tests/release_only_tests.txt).
  # MIDDLEWARE: a robot link's own cases, label `unit-middleware` (one label: a list would not
  # survive gtest_discover_tests); only the release build, with ROS 1 and ROS 2, has them and runs
  # them all.
  set(properties LABELS unit)
  if(ARG_MIDDLEWARE)
    set(properties LABELS unit-middleware)
  endif()
  if(ARG_COST)
    list(APPEND properties COST ${ARG_COST})
  endif()
  if(MAPLESS_SANITIZE AND ARG_SANITIZE_ENV)
    list(APPEND properties ENVIRONMENT "${ARG_SANITIZE_ENV}")
  endif()
  gtest_discover_tests(${ARG_NAME} WORKING_DIRECTORY ${PROJECT_BINARY_DIR} DISCOVERY_TIMEOUT 60
                       PROPERTIES ${properties})
  # README command 2 runs in the release build only the cases that tests/release_only_tests.txt
  # names (and the middleware's): with MAPLESS_RELEASE_ONLY_TESTS, the binaries that have none
  # are left out of `all` (scripts/test.sh; about 100 CPU-seconds of compiling).
  if(MAPLESS_RELEASE_ONLY_TESTS AND NOT ARG_MIDDLEWARE AND NOT MAPLESS_SANITIZE)
    mapless_has_release_only_case(has ${ARG_SRCS})
    if(NOT has)
      set_target_properties(${ARG_NAME} PROPERTIES EXCLUDE_FROM_ALL ON)
    endif()
  endif()
  # And the sanitizer build leaves out the binaries whose every case is release-only.
  if(MAPLESS_RELEASE_ONLY_TESTS AND NOT ARG_MIDDLEWARE AND MAPLESS_SANITIZE)
    mapless_only_release_only_cases(only ${ARG_SRCS})
    if(only)
      set_target_properties(${ARG_NAME} PROPERTIES EXCLUDE_FROM_ALL ON)
    endif()
  endif()
endfunction()

# Sets `out` to TRUE when the sources define cases and tests/release_only_tests.txt names each.
function(mapless_only_release_only_cases out)
  file(STRINGS ${PROJECT_SOURCE_DIR}/tests/release_only_tests.txt lines REGEX "^[A-Za-z]")
  set(listed "")
  foreach(line ${lines})
    string(REGEX MATCH "^[A-Za-z0-9_]+\\.[A-Za-z0-9_]+" name "${line}")
    list(APPEND listed "${name}")
  endforeach()
  set(cases 0)
  foreach(src ${ARGN})
    get_filename_component(path ${src} ABSOLUTE)
    file(READ ${path} text)
    string(REGEX MATCHALL "TEST(_F|_P)?\\([A-Za-z0-9_]+, *[A-Za-z0-9_]+\\)" found "${text}")
    foreach(f ${found})
      string(REGEX REPLACE "TEST(_F|_P)?\\(([A-Za-z0-9_]+), *([A-Za-z0-9_]+)\\)" "\\2.\\3" name "${f}")
      math(EXPR cases "${cases} + 1")
      if(NOT name IN_LIST listed)
        set(${out} FALSE PARENT_SCOPE)
        return()
      endif()
    endforeach()
  endforeach()
  if(cases GREATER 0)
    set(${out} TRUE PARENT_SCOPE)
  else()
    set(${out} FALSE PARENT_SCOPE)
  endif()
endfunction()

# Sets `out` to TRUE when one of the sources defines a case named in tests/release_only_tests.txt.
function(mapless_has_release_only_case out)
  file(STRINGS ${PROJECT_SOURCE_DIR}/tests/release_only_tests.txt lines REGEX "^[A-Za-z]")
  set(${out} FALSE PARENT_SCOPE)
  foreach(src ${ARGN})
    get_filename_component(path ${src} ABSOLUTE)
    file(READ ${path} text)
    foreach(line ${lines})
      string(REGEX MATCH "^([A-Za-z0-9_]+)\\.([A-Za-z0-9_]+)" name "${line}")
      if(name AND text MATCHES "TEST(_F)?\\(${CMAKE_MATCH_1}, *${CMAKE_MATCH_2}\\)")
        set(${out} TRUE PARENT_SCOPE)
        return()
      endif()
    endforeach()
  endforeach()
endfunction()

# mapless_register_middleware(MODULE HEADER FUNCTION): a module that implements a middleware of the
# robot link (src/mapless/robot/middleware.h) names its registration function, e.g.
#   mapless_register_middleware(ros1 mapless/ros1/register.h mapless::ros1::RegisterMiddleware)
# The command line calls every registered one (apps/builtin_middlewares.cc.in) and links the
# module: a middleware that is not built is simply not there, with no #ifdef in the code using it.
function(mapless_register_middleware module header function)
  set_property(GLOBAL APPEND PROPERTY MAPLESS_MIDDLEWARE_MODULES ${module})
  set_property(GLOBAL APPEND PROPERTY MAPLESS_MIDDLEWARE_HEADERS ${header})
  set_property(GLOBAL APPEND PROPERTY MAPLESS_MIDDLEWARE_FUNCTIONS ${function})
endfunction()

# Writes the source of BuiltinMiddlewares() (apps/builtin_middlewares.h) into `out_var`'s file and
# links every registered middleware module to `target`.
function(mapless_builtin_middlewares target template out)
  get_property(modules GLOBAL PROPERTY MAPLESS_MIDDLEWARE_MODULES)
  get_property(headers GLOBAL PROPERTY MAPLESS_MIDDLEWARE_HEADERS)
  get_property(functions GLOBAL PROPERTY MAPLESS_MIDDLEWARE_FUNCTIONS)
  set(MAPLESS_MIDDLEWARE_INCLUDES "")
  set(MAPLESS_MIDDLEWARE_CALLS "")
  foreach(h IN LISTS headers)
    string(APPEND MAPLESS_MIDDLEWARE_INCLUDES "#include \"${h}\"\n")
  endforeach()
  foreach(f IN LISTS functions)
    string(APPEND MAPLESS_MIDDLEWARE_CALLS "    ${f}(&r);\n")
  endforeach()
  configure_file(${template} ${out} @ONLY)
  foreach(m IN LISTS modules)
    target_link_libraries(${target} PRIVATE mapless::${m})
  endforeach()
endfunction()
