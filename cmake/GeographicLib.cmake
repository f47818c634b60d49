# Debian's GeographicLib ships a find module (/usr/share/cmake/geographiclib) that sets variables only: expose the
# library as one imported target, roamlab::geographiclib, so that the installed roamlab targets name a target instead
# of a path (roamlabConfig.cmake includes this file for the components that link it).
list(APPEND CMAKE_MODULE_PATH /usr/share/cmake/geographiclib)
find_package(GeographicLib REQUIRED)
if(NOT TARGET roamlab::geographiclib)
  add_library(roamlab::geographiclib INTERFACE IMPORTED)
  set_target_properties(roamlab::geographiclib PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${GeographicLib_INCLUDE_DIRS}"
    INTERFACE_LINK_LIBRARIES "${GeographicLib_LIBRARIES}")
endif()
