# lidarshop_add_module(NAME name [DEPS module...] [LIBS target...])
#
# One folder of src/lidarshop is one module: every .cc in it that is not a *_test.cc goes into the static library
# lidarshop_<name>; the *_test.cc files make one test program, lidarshop_<name>_tests, linked against the module,
# its dependencies and lidarshop_testing (when TEST_DEPS names it), and each is its own ctest. Files are globbed
# so that adding a source file needs no CMake edit.
# Headers are found as "lidarshop/<module>/x.h": under src/ in the build, under PREFIX/include once installed
# (cmake/LidarshopInstall.cmake).
include(GNUInstallDirs)
set(LIDARSHOP_ALL_MODULES "" CACHE INTERNAL "")

function(lidarshop_add_module)
  cmake_parse_arguments(ARG "" "NAME" "DEPS;LIBS;TEST_DEPS;TEST_LIBS" ${ARGN})
  set(target lidarshop_${ARG_NAME})
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  file(GLOB tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_test.cc)
  if(tests)
    list(REMOVE_ITEM sources ${tests})
  endif()
  set(dep_targets "")
  foreach(dep ${ARG_DEPS})
    list(APPEND dep_targets lidarshop_${dep})
  endforeach()
  if(sources)
    add_library(${target} STATIC ${sources})
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                                $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} PUBLIC ${dep_targets} ${ARG_LIBS})
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter -Wno-psabi -fno-math-errno)
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                                   $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} INTERFACE ${dep_targets} ${ARG_LIBS})
  endif()
  set(LIDARSHOP_ALL_MODULES ${LIDARSHOP_ALL_MODULES} ${target} CACHE INTERNAL "")

  if(LIDARSHOP_BUILD_TESTS AND tests)
    # One test program a module (lidarshop_<module>_tests), its test files compiled in unity batches like the
    # library: they parse gtest, Eigen and OpenCV once a batch, not once a file. Each test file is still its own
    # ctest, named after the file, running that file's tests (--gtest_filter with their names).
    set(test_target lidarshop_${ARG_NAME}_tests)
    set(test_dep_targets "")
    foreach(dep ${ARG_TEST_DEPS})
      list(APPEND test_dep_targets lidarshop_${dep})
    endforeach()
    add_executable(${test_target} ${tests})
    target_link_libraries(${test_target} PRIVATE ${target} ${test_dep_targets} ${ARG_TEST_LIBS} GTest::gtest
                                                 GTest::gmock GTest::gtest_main)
    target_compile_definitions(${test_target} PRIVATE
      LIDARSHOP_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      LIDARSHOP_SHARED_DATA_DIR="${LIDARSHOP_SHARED_DATA_DIR}")
    foreach(test_source ${tests})
      get_filename_component(test_name ${test_source} NAME_WE)
      lidarshop_gtest_filter(${test_source} filter)
      # Test file names are unique across modules, so the file name is the ctest name.
      add_test(NAME ${test_name} COMMAND ${test_target} --gtest_filter=${filter}
               WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
      set_tests_properties(${test_name} PROPERTIES TIMEOUT 600 LABELS ${ARG_NAME})
    endforeach()
  endif()
endfunction()

# lidarshop_gtest_filter(TEST_SOURCE OUT_VAR): the --gtest_filter that selects the tests TEST_SOURCE defines
# (Suite.Name for TEST and TEST_F, */Suite.Name/* for TEST_P). A line starting with TEST that is not one
# `TEST(Suite, Name)` on one line stops the configure: a test the filter missed would silently never run
# (tests/gtest_filters_test.py checks the result). The file is a configure dependency, so a test added to it is
# in the filter at the next build.
function(lidarshop_gtest_filter test_source out_var)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${test_source})
  file(STRINGS ${test_source} lines REGEX "^(TYPED_)?TEST")
  set(names "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^TEST(_F|_P)?\\( *([A-Za-z0-9_]+) *, *([A-Za-z0-9_]+) *\\)")
      if(CMAKE_MATCH_1 STREQUAL "_P")
        list(APPEND names "*/${CMAKE_MATCH_2}.${CMAKE_MATCH_3}/*")
      else()
        list(APPEND names "${CMAKE_MATCH_2}.${CMAKE_MATCH_3}")
      endif()
    else()
      message(FATAL_ERROR "${test_source}: '${line}' is not TEST(Suite, Name), TEST_F or TEST_P on one line; "
                          "the module's ctest filter cannot name it")
    endif()
  endforeach()
  if(NOT names)
    message(FATAL_ERROR "${test_source}: no TEST(Suite, Name) line found")
  endif()
  list(JOIN names ":" filter)
  set(${out_var} "${filter}" PARENT_SCOPE)
endfunction()
