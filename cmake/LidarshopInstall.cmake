# `cmake --install BUILD [--prefix PREFIX]` puts the library in place as a CMake package (component Development):
#   PREFIX/lib/liblidarshop_<module>.a              the module libraries the `lidarshop` target links (not
#                                                   `testing`: test fixtures)
#   PREFIX/include/lidarshop/<module>/*.h           their public headers: not *_test*.h, not a header whose
#                                                   opening comment says it is internal to its module
#   PREFIX/lib/cmake/lidarshop/lidarshopConfig.cmake, lidarshopConfigVersion.cmake, lidarshopTargets*.cmake and
#                                                   LidarshopExternal.cmake (libraries without a package)
# A user writes find_package(lidarshop REQUIRED) and links lidarshop::lidarshop (or one module, lidarshop::io);
# the config finds what the modules' link interface names (cmake/lidarshopConfig.cmake.in). The ctest
# `install_test` (tests/install/) installs a build into a temporary prefix and builds a program against it.
include(CMakePackageConfigHelpers)

set(LIDARSHOP_CONFIG_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/lidarshop)
get_target_property(lidarshop_installed_modules lidarshop INTERFACE_LINK_LIBRARIES)
set(header_modules "")
set(header_dirs "")
foreach(module_target ${lidarshop_installed_modules})
  string(REGEX REPLACE "^lidarshop_" "" module ${module_target})
  set_target_properties(${module_target} PROPERTIES EXPORT_NAME ${module})
  get_target_property(module_dir ${module_target} SOURCE_DIR)
  list(APPEND header_modules ${module})
  list(APPEND header_dirs ${module_dir})
endforeach()
# The public headers are chosen when installing (cmake/LidarshopInstallHeaders.cmake), from the folders as they are.
install(CODE "set(LIDARSHOP_HEADER_MODULES \"${header_modules}\")
set(LIDARSHOP_HEADER_DIRS \"${header_dirs}\")
set(LIDARSHOP_HEADER_DESTINATION \"${CMAKE_INSTALL_INCLUDEDIR}\")" COMPONENT Development)
install(SCRIPT ${PROJECT_SOURCE_DIR}/cmake/LidarshopInstallHeaders.cmake COMPONENT Development)

# Eigen's alignment is part of the library's ABI: a struct holding an Eigen::Matrix4d (Scan) has another size and
# layout when Eigen aligns to 32 bytes (-mavx, -march=native) than to 16, and heap blocks are freed the way they
# were allocated. The installed targets pin the values the library was compiled with (read from a probe compiled
# with the library's flags), so a program built with other flags still agrees. The build tree is not changed.
set(probe_dir ${PROJECT_BINARY_DIR}/CMakeFiles/lidarshop_eigen_abi)
file(WRITE ${probe_dir}/probe.cc [=[
#include <Eigen/Core>
#define LIDARSHOP_TEXT2(x) #x
#define LIDARSHOP_TEXT(x) LIDARSHOP_TEXT2(x)
extern const char kLidarshopEigenAbi[] = "lidarshop_eigen_abi=" LIDARSHOP_TEXT(EIGEN_MAX_ALIGN_BYTES) ","
                                         LIDARSHOP_TEXT(EIGEN_MAX_STATIC_ALIGN_BYTES);
]=])
get_directory_property(library_compile_options DIRECTORY ${PROJECT_SOURCE_DIR} COMPILE_OPTIONS)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)
set(CMAKE_TRY_COMPILE_CONFIGURATION ${CMAKE_BUILD_TYPE})  # CMAKE_CXX_FLAGS_<build type> too (-march there)
try_compile(eigen_probe_compiled ${probe_dir}/build SOURCES ${probe_dir}/probe.cc
            COMPILE_DEFINITIONS ${library_compile_options} LINK_LIBRARIES Eigen3::Eigen
            CXX_STANDARD ${CMAKE_CXX_STANDARD} COPY_FILE ${probe_dir}/probe.a OUTPUT_VARIABLE probe_output)
unset(CMAKE_TRY_COMPILE_TARGET_TYPE)
unset(CMAKE_TRY_COMPILE_CONFIGURATION)
set(eigen_abi "")
if(eigen_probe_compiled)
  file(STRINGS ${probe_dir}/probe.a eigen_abi REGEX "lidarshop_eigen_abi=[0-9]+,[0-9]+")
endif()
if(NOT eigen_abi MATCHES "lidarshop_eigen_abi=([0-9]+),([0-9]+)")
  message(FATAL_ERROR "lidarshop: could not read Eigen's alignment under the library's flags:\n${probe_output}")
endif()
target_compile_definitions(lidarshop_util INTERFACE $<INSTALL_INTERFACE:EIGEN_MAX_ALIGN_BYTES=${CMAKE_MATCH_1}
                                                                   EIGEN_MAX_STATIC_ALIGN_BYTES=${CMAKE_MATCH_2}>)

install(TARGETS lidarshop ${lidarshop_installed_modules} EXPORT lidarshopTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT Development)
install(EXPORT lidarshopTargets NAMESPACE lidarshop:: DESTINATION ${LIDARSHOP_CONFIG_INSTALL_DIR}
        COMPONENT Development)
configure_package_config_file(cmake/lidarshopConfig.cmake.in ${PROJECT_BINARY_DIR}/lidarshopConfig.cmake
                              INSTALL_DESTINATION ${LIDARSHOP_CONFIG_INSTALL_DIR})
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/lidarshopConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/lidarshopConfig.cmake ${PROJECT_BINARY_DIR}/lidarshopConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/LidarshopExternal.cmake
        DESTINATION ${LIDARSHOP_CONFIG_INSTALL_DIR} COMPONENT Development)
