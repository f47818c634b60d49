# SuiteSparse 5.12 (Debian 12) ships neither a CMake config nor pkg-config files: find CHOLMOD and its ordering
# libraries by hand and expose them as one imported target, roamlab::cholmod (not SuiteSparse::CHOLMOD, which
# Ceres' own FindSuiteSparse defines for the benchmark).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
foreach(lib cholmod amd colamd camd ccolamd suitesparseconfig)
  find_library(SUITESPARSE_${lib}_LIBRARY ${lib} REQUIRED)
  list(APPEND SUITESPARSE_LIBRARIES ${SUITESPARSE_${lib}_LIBRARY})
endforeach()
if(NOT TARGET roamlab::cholmod)
  add_library(roamlab::cholmod INTERFACE IMPORTED)
  set_target_properties(roamlab::cholmod PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SUITESPARSE_LIBRARIES}")
endif()
