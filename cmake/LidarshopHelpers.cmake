# lidarshop_add_module(NAME name [DEPS module...] [LIBS target...])
#
# One folder of src/lidarshop is one module: every .cc in it that is not a *_test.cc goes into the static library
# lidarshop_<name>; every *_test.cc becomes its own test executable and its own ctest, linked against the module,
# its dependencies and lidarshop_testing (when TEST_DEPS names it). Files are globbed so that adding a source file
# needs no CMake edit.
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

  if(LIDARSHOP_BUILD_TESTS)
    foreach(test_source ${tests})
      get_filename_component(test_name ${test_source} NAME_WE)
      # Test file names are unique across modules, so the file name is the ctest name.
      set(test_target ${test_name})
      set(test_dep_targets "")
      foreach(dep ${ARG_TEST_DEPS})
        list(APPEND test_dep_targets lidarshop_${dep})
      endforeach()
      add_executable(${test_target} ${test_source})
      target_link_libraries(${test_target} PRIVATE ${target} ${test_dep_targets} ${ARG_TEST_LIBS} GTest::gtest
                                                   GTest::gmock GTest::gtest_main)
      target_compile_definitions(${test_target} PRIVATE
        LIDARSHOP_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
        LIDARSHOP_SHARED_DATA_DIR="${LIDARSHOP_SHARED_DATA_DIR}")
      add_test(NAME ${test_target} COMMAND ${test_target} WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
      set_tests_properties(${test_target} PROPERTIES TIMEOUT 600 LABELS ${ARG_NAME})
    endforeach()
  endif()
endfunction()
