# `cmake --install BUILD --prefix P` (GNUInstallDirs), for environment modules and Spack:
#   P/bin/superball                              the program
#   P/lib/pythonX.Y/site-packages/superball      the Python module (src/python/CMakeLists.txt)
#   P/share/superball/jobs/{slurm,pbs}           the batch scripts (they run P/bin/superball)
#   P/share/superball/analysis                   the figure scripts
#   P/include/superball/superball.hpp            the public C++ API (src/api): the one header
#   P/lib/libsuperball_*.a                       the libraries: the API's and those it is made of
#   P/lib/cmake/superball                        find_package(superball): superball::api
# The internal headers are not installed: what a program may use is the API, what it may not
# cannot be included.
# Nothing installed refers to the build tree.
include(CMakePackageConfigHelpers)

install(TARGETS superball RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT program)

set(superball_libraries core job measures mpi io run api)
set(exported superball_flags)
foreach(name ${superball_libraries})
  set_target_properties(superball_${name} PROPERTIES EXPORT_NAME ${name})
  list(APPEND exported superball_${name})
endforeach()
# The kernel variants are in libsuperball_core.a; their targets are exported for its link
# interface only.
foreach(variant ${SUPERBALL_SIMD_VARIANTS})
  set_target_properties(superball_simd_${variant} PROPERTIES EXPORT_NAME simd_${variant})
  list(APPEND exported superball_simd_${variant})
endforeach()
set_target_properties(superball_flags PROPERTIES EXPORT_NAME flags)
install(TARGETS ${exported} EXPORT superballTargets COMPONENT development
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        OBJECTS DESTINATION ${CMAKE_INSTALL_LIBDIR}/superball/objects
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES src/api/superball/superball.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/superball COMPONENT development)
set(package_dir ${CMAKE_INSTALL_LIBDIR}/cmake/superball)
install(EXPORT superballTargets NAMESPACE superball:: DESTINATION ${package_dir} COMPONENT development)
configure_package_config_file(cmake/superballConfig.cmake.in ${CMAKE_BINARY_DIR}/superballConfig.cmake
                              INSTALL_DESTINATION ${package_dir})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/superballConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/superballConfig.cmake ${CMAKE_BINARY_DIR}/superballConfigVersion.cmake
        DESTINATION ${package_dir} COMPONENT development)

install(PROGRAMS jobs/slurm/explore.sbatch DESTINATION ${CMAKE_INSTALL_DATADIR}/superball/jobs/slurm COMPONENT scripts)
install(PROGRAMS jobs/pbs/explore.pbs DESTINATION ${CMAKE_INSTALL_DATADIR}/superball/jobs/pbs COMPONENT scripts)
file(GLOB analysis_scripts CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/analysis/*.py)
install(PROGRAMS ${analysis_scripts} DESTINATION ${CMAKE_INSTALL_DATADIR}/superball/analysis COMPONENT scripts)
file(GLOB notebooks CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/analysis/*.ipynb)
install(FILES ${notebooks} DESTINATION ${CMAKE_INSTALL_DATADIR}/superball/analysis COMPONENT scripts)
