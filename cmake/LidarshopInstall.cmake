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
