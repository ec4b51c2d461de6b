# The installed package (`cmake --install build --prefix P`): the four libraries the programs use, as static
# libraries with their headers, and a CMake package for them, so that another project writes
#   find_package(geomint CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE geomint::core)   # or geomint::studies, geomint::modified, geomint::plots
# (docs/cmake-package.md; tests/consumer/ is such a project, built against an install by the tests). The programs,
# the Python module (pip, README) and the tests are not installed.
include(CMakePackageConfigHelpers)
set(GEOMINT_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/geomint)

# geomint::<name> here too, so that code moved between this tree and a consumer links the same names
foreach(name core studies modified plots)
  set_target_properties(geomint_${name} PROPERTIES EXPORT_NAME ${name})
  add_library(geomint::${name} ALIAS geomint_${name})
endforeach()
install(TARGETS geomint_core geomint_studies geomint_modified geomint_plots EXPORT geomintTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})  # their include directory is each one's INSTALL_INTERFACE
# Every public header is under <library>/include/geomint/, so the four trees merge into one include/geomint/. None
# includes a generated file (those stay in the libraries' sources).
foreach(dir core studies modified_equations plots)
  install(DIRECTORY ${CMAKE_SOURCE_DIR}/${dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
install(EXPORT geomintTargets NAMESPACE geomint:: DESTINATION ${GEOMINT_INSTALL_CMAKEDIR})

# What the config file must find again: the formulas' GiNaC, and MPI, which the core links privately but which a
# consumer of the static library must link all the same.
if(GEOMINT_SYMBOLIC)
  set(GEOMINT_CONFIG_GINAC ON)
else()
  set(GEOMINT_CONFIG_GINAC OFF)
endif()
if(GEOMINT_HAVE_MPI)
  set(GEOMINT_CONFIG_MPI ON)
else()
  set(GEOMINT_CONFIG_MPI OFF)
endif()
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/geomintConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/geomintConfig.cmake
                              INSTALL_DESTINATION ${GEOMINT_INSTALL_CMAKEDIR})
# 0.x: a new minor version may change the interfaces
write_basic_package_version_file(${CMAKE_BINARY_DIR}/geomintConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/geomintConfig.cmake ${CMAKE_BINARY_DIR}/geomintConfigVersion.cmake
        DESTINATION ${GEOMINT_INSTALL_CMAKEDIR})
