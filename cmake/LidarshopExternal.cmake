# The external libraries that ship no CMake package of their own: LZF (PCD's binary_compressed), the
# Boykov–Kolmogorov max-flow library (inpaint, segment) and CHOLMOD (poisson). Each becomes an imported target
# found by name, with the Debian locations as hints only, so that the installed lidarshop package
# (lidarshopConfig.cmake includes this file too) finds them again on the machine that uses it:
#   lidarshop_external::lzf       liblzf           (#include <liblzf/lzf.h>)
#   lidarshop_external::maxflow   libmaxflow       (#include <maxflow/graph.h>)
#   lidarshop_external::cholmod   libcholmod       (#include <cholmod.h>)
# Their headers are included by library sources only (privately), so a user of the installed package needs the
# libraries alone; the build finds the header folders in the top CMakeLists.txt. Sets
# LIDARSHOP_EXTERNAL_MISSING to the libraries it could not find.
set(LIDARSHOP_EXTERNAL_MISSING "")

function(_lidarshop_external name library_names)
  set(target lidarshop_external::${name})
  if(TARGET ${target})
    return()
  endif()
  string(TOUPPER ${name} upper)
  find_library(LIDARSHOP_${upper}_LIBRARY NAMES ${library_names} HINTS /usr/lib/x86_64-linux-gnu)
  if(NOT LIDARSHOP_${upper}_LIBRARY)
    set(LIDARSHOP_EXTERNAL_MISSING ${LIDARSHOP_EXTERNAL_MISSING} "lib${name} (library ${library_names})"
        PARENT_SCOPE)
    return()
  endif()
  add_library(${target} UNKNOWN IMPORTED)
  set_target_properties(${target} PROPERTIES IMPORTED_LOCATION ${LIDARSHOP_${upper}_LIBRARY})
endfunction()

_lidarshop_external(lzf lzf)
_lidarshop_external(maxflow maxflow)
_lidarshop_external(cholmod cholmod)
