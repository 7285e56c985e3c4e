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
foreach(module_target ${lidarshop_installed_modules})
  string(REGEX REPLACE "^lidarshop_" "" module ${module_target})
  set_target_properties(${module_target} PROPERTIES EXPORT_NAME ${module})
  get_target_property(module_dir ${module_target} SOURCE_DIR)
  file(GLOB module_headers CONFIGURE_DEPENDS ${module_dir}/*.h)
  set(public_headers "")
  foreach(header ${module_headers})
    # The opening comment (the first 2000 bytes) says whether a header is internal ("Internal to the io module").
    file(STRINGS ${header} internal_mark LIMIT_INPUT 2000 REGEX "[Ii]nternals? (to|of) ")
    if(NOT header MATCHES "_test[A-Za-z0-9_]*\\.h$" AND NOT internal_mark)
      list(APPEND public_headers ${header})
    endif()
  endforeach()
  install(FILES ${public_headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/lidarshop/${module}
          COMPONENT Development)
endforeach()

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
