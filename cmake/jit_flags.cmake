# The record of how this build compiles a formula shape, for the shapes compiled at run time
# (core/include/geomint/formula/jit.hpp): generated/jit/flags.txt holds the compiler, then one argument per line (the
# build type's flags, the language level, and the modified-equations library's options, definitions and include
# folders: everything a shape's units include, transitively from the libraries it links), then "--link--" and the
# link's arguments, then "--formulas--" and the libraries the formulas' unit needs (GiNaC).
string(TOUPPER "${CMAKE_BUILD_TYPE}" _geomint_config)
separate_arguments(_geomint_base UNIX_COMMAND "${CMAKE_CXX_FLAGS} ${CMAKE_CXX_FLAGS_${_geomint_config}}")
list(JOIN _geomint_base "\n" _geomint_base)
set(_geomint_link "")
if(GEOMINT_SANITIZE)
  set(_geomint_link "-fsanitize=address,undefined")
endif()
set(_t geomint_modified)
# the compiler's own folders stay out, as CMake leaves them out of its command lines (-I/usr/include breaks the
# #include_next of the C++ library's headers)
set(_geomint_implicit "")
foreach(dir ${CMAKE_CXX_IMPLICIT_INCLUDE_DIRECTORIES})
  string(REGEX REPLACE "([][+.*()^$?|\\\\])" "\\\\\\1" dir "${dir}")
  list(APPEND _geomint_implicit "^${dir}$")
endforeach()
list(JOIN _geomint_implicit "|" _geomint_implicit)
set(_geomint_includes "$<TARGET_PROPERTY:${_t},INCLUDE_DIRECTORIES>")
if(_geomint_implicit)
  set(_geomint_includes "$<FILTER:${_geomint_includes},EXCLUDE,${_geomint_implicit}>")
endif()
set(_geomint_formulas "")
if(GEOMINT_SYMBOLIC)
  set(_geomint_formulas "$<JOIN:$<TARGET_PROPERTY:PkgConfig::GINAC,INTERFACE_LINK_LIBRARIES>,\n>")
endif()
file(GENERATE OUTPUT ${CMAKE_BINARY_DIR}/generated/jit/flags.txt CONTENT "${CMAKE_CXX_COMPILER}
${_geomint_base}
-std=c++${CMAKE_CXX_STANDARD}
-fPIC
$<JOIN:$<TARGET_PROPERTY:${_t},COMPILE_OPTIONS>,\n>
-D$<JOIN:$<TARGET_PROPERTY:${_t},COMPILE_DEFINITIONS>,\n-D>
-I$<JOIN:${_geomint_includes},\n-I>
--link--
${_geomint_link}
--formulas--
${_geomint_formulas}
")
