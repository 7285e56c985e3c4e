# Run by `cmake --install` (cmake/LidarshopInstall.cmake passes LIDARSHOP_HEADER_MODULES, the module names, and
# LIDARSHOP_HEADER_DIRS, their source folders, and LIDARSHOP_HEADER_DESTINATION, include/ under the prefix):
# installs the public headers of each module as they are at install time, so that a header added, removed or
# marked internal needs no new configure. Public: every *.h of the folder but the test helpers (*_test*.h) and
# the headers whose opening comment (the first 2000 bytes) says they are internal ("Internal to the io module").
foreach(module dir IN ZIP_LISTS LIDARSHOP_HEADER_MODULES LIDARSHOP_HEADER_DIRS)
  file(GLOB headers ${dir}/*.h)
  set(public_headers "")
  foreach(header ${headers})
    file(STRINGS ${header} internal_mark LIMIT_INPUT 2000 REGEX "[Ii]nternals? (to|of) ")
    if(NOT header MATCHES "_test[A-Za-z0-9_]*\\.h$" AND NOT internal_mark)
      list(APPEND public_headers ${header})
    endif()
  endforeach()
  file(INSTALL DESTINATION "${CMAKE_INSTALL_PREFIX}/${LIDARSHOP_HEADER_DESTINATION}/lidarshop/${module}" TYPE FILE
       FILES ${public_headers})
endforeach()
