# The installed CMake package, tested as a user meets it: `cmake --install` of this build into a fresh prefix, then
# tests/consumer/ (find_package(geomint CONFIG REQUIRED)) configured, built against that prefix alone and run.
# cmake -DBUILD=<build dir> -DSOURCE=<source dir> -DWORK=<scratch dir> -DCXX=<compiler> [-DLAUNCHER=ccache]
#       -DGENERATOR=<generator> -DLIBDIR=<CMAKE_INSTALL_LIBDIR> -P consumer.cmake
foreach(var BUILD SOURCE WORK CXX GENERATOR LIBDIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "consumer.cmake: -D${var}=... is required")
  endif()
endforeach()

# from scratch every time: a stale prefix or consumer build must not pass for this build's
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
set(consumer ${WORK}/consumer)

include(${SOURCE}/cmake/run_step.cmake)

run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix})
# CMAKE_FIND_USE_PACKAGE_REGISTRY off and the prefix given alone: the package found must be the one just installed
run("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE}/tests/consumer -B ${consumer} -G "${GENERATOR}"
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
file(STRINGS ${consumer}/CMakeCache.txt found REGEX "^geomint_DIR:")
if(NOT found STREQUAL "geomint_DIR:PATH=${prefix}/${LIBDIR}/cmake/geomint")
  message(FATAL_ERROR "the consumer found another geomint: ${found}")
endif()
run("building the consumer" ${CMAKE_COMMAND} --build ${consumer})
run("running the consumer" ${consumer}/consumer)
message("${output}")
