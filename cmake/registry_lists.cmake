# The lists the build generates translation units from, read once in one way for core/ and modified_equations/.
#
# geomint_registry_systems(VAR): the systems of core/src/systems.def, one "header:Type" per
#   GEOMINT_SYSTEM(header, Type) line (the header must exist under core/include/geomint/systems/).
# geomint_formula_shapes(VAR): the shapes the build compiles, one "n:m:h:modified:light" per
#   GEOMINT_FORMULA_SHAPE(n, m, holonomic 0/1, modified equations 0/1) line of core/src/formula/shapes.def (n <= 12,
#   m <= 6 and m < n, as the reader takes them: formula/model.hpp; light 1 when the line says "// light"), and the
#   same lines in generated/formula/shapes_compiled.def, which the registries include. A sanitizer build that compiles
#   its own template units compiles only the shapes with modified equations: the ones its tests use; the others are
#   the same templates at other sizes. One that takes them from a release build (below) has them all.
# Both make the configuration re-run when their file changes.

function(geomint_registry_systems var)
  set(def ${CMAKE_SOURCE_DIR}/core/src/systems.def)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${def})
  file(STRINGS ${def} lines REGEX "^GEOMINT_SYSTEM\\(")
  set(items "")
  foreach(line ${lines})
    if(NOT line MATCHES "^GEOMINT_SYSTEM\\(([a-z0-9_]+), *([A-Za-z0-9_]+)\\)")
      message(FATAL_ERROR "systems.def: cannot read '${line}' (expected GEOMINT_SYSTEM(header, Type))")
    endif()
    if(NOT EXISTS ${CMAKE_SOURCE_DIR}/core/include/geomint/systems/${CMAKE_MATCH_1}.hpp)
      message(FATAL_ERROR "systems.def: no header core/include/geomint/systems/${CMAKE_MATCH_1}.hpp")
    endif()
    list(APPEND items "${CMAKE_MATCH_1}:${CMAKE_MATCH_2}")
  endforeach()
  set(${var} ${items} PARENT_SCOPE)
endfunction()

function(geomint_formula_shapes var)
  set(def ${CMAKE_SOURCE_DIR}/core/src/formula/shapes.def)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${def})
  file(STRINGS ${def} lines REGEX "^GEOMINT_FORMULA_SHAPE\\(")
  set(items "")
  set(compiled "")
  foreach(line ${lines})
    set(shape_ok OFF)
    if(line MATCHES "^GEOMINT_FORMULA_SHAPE\\(([1-9]|1[0-2]), *([0-6]), *([01]), *([01])\\)")
      if(CMAKE_MATCH_2 LESS CMAKE_MATCH_1 AND NOT (CMAKE_MATCH_2 EQUAL 0 AND CMAKE_MATCH_3 EQUAL 1))
        set(shape_ok ON)
      endif()
    endif()
    if(NOT shape_ok)
      message(FATAL_ERROR "shapes.def: cannot read '${line}' (expected GEOMINT_FORMULA_SHAPE(n, m, holonomic, modified): "
                          "n = 1..12 coordinates, m = 0..6 rows and fewer than n, holonomic 1 only with rows, modified 0 or 1)")
    endif()
    if(GEOMINT_SANITIZE AND NOT GEOMINT_TEMPLATE_UNITS_FROM AND CMAKE_MATCH_4 STREQUAL "0")
      continue()
    endif()
    set(shape "${CMAKE_MATCH_1}:${CMAKE_MATCH_2}:${CMAKE_MATCH_3}:${CMAKE_MATCH_4}")
    string(FIND "${line}" "// light" light_at)  # not MATCHES: it would clear the shape's matches
    if(light_at GREATER -1)
      list(APPEND items "${shape}:1")
    else()
      list(APPEND items "${shape}:0")
    endif()
    string(APPEND compiled "${line}\n")
  endforeach()
  # rewritten only when it changes, so that a reconfiguration recompiles nothing
  file(WRITE ${CMAKE_BINARY_DIR}/generated/formula/shapes_compiled.def.new
       "// Generated from core/src/formula/shapes.def: the shapes this build compiles.\n${compiled}")
  configure_file(${CMAKE_BINARY_DIR}/generated/formula/shapes_compiled.def.new
                 ${CMAKE_BINARY_DIR}/generated/formula/shapes_compiled.def COPYONLY)
  set(${var} ${items} PARENT_SCOPE)
endfunction()

# The generated translation units instantiate the generic templates once per system and shape. In the sanitizer
# build they are compiled with AddressSanitizer but without UndefinedBehaviorSanitizer, whose checks on every
# operation of these templates took 79 s against 45 s for one unit (KnifeEdge's modified equations, measured):
# the same templates are compiled with both sanitizers in the tests that instantiate them (the system tests step
# every system with every scheme), and the hand-written code keeps both.
function(geomint_generated_units)
  if(GEOMINT_SANITIZE)
    set_property(SOURCE ${ARGN} APPEND PROPERTY COMPILE_OPTIONS -fno-sanitize=undefined)
  endif()
endfunction()

# The template units from a release build. They are half of the sanitizer build's compile time (34 of its units:
# the build takes 12 minutes on 2 cores without them, about 23 with them) and, compiled with AddressSanitizer alone,
# checked least of all: the sanitizer suite's own instrumented copies of these templates are the tests'
# instantiations, which carry both sanitizers, and the linker keeps those (an object of the program comes before
# any archive member). So with
# GEOMINT_TEMPLATE_UNITS_FROM=<release build of the same tree> (`make sanitize` passes its own release build, built
# first) the sanitizer build links that build's objects of these units, uninstrumented as a system library is,
# and compiles everything written by hand, the tests and the programs with both sanitizers. -O3 and -Og give the
# same bits here (no fast-math, no contraction), so the objects are interchangeable; Eigen's allocator is made the
# same on both sides (CMakeLists.txt: a bad free otherwise).
#
# geomint_release_objects(library): in a release build, the list of the library's objects, for a sanitizer build to
#   read (generated/objects_<library>.txt, written at generation).
# geomint_template_units(library VAR sources...): VAR = the sources to compile, or, from a release build, its
#   objects of these sources.
function(geomint_release_objects library)
  if(NOT GEOMINT_SANITIZE)
    file(GENERATE OUTPUT ${CMAKE_BINARY_DIR}/generated/objects_${library}.txt CONTENT "$<TARGET_OBJECTS:${library}>")
  endif()
endfunction()

function(geomint_template_units library var)
  if(NOT (GEOMINT_SANITIZE AND GEOMINT_TEMPLATE_UNITS_FROM))
    set(${var} ${ARGN} PARENT_SCOPE)
    return()
  endif()
  set(manifest ${GEOMINT_TEMPLATE_UNITS_FROM}/generated/objects_${library}.txt)
  if(NOT EXISTS ${manifest})
    message(FATAL_ERROR "GEOMINT_TEMPLATE_UNITS_FROM=${GEOMINT_TEMPLATE_UNITS_FROM}: no ${manifest}; "
                        "configure and build a release build of this tree there first (make build)")
  endif()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${manifest})
  file(READ ${manifest} objects)
  set(found "")
  foreach(src ${ARGN})
    # a source of this folder is named from it (tests/main.cpp: geomint_tests.dir/main.cpp.o), a generated one
    # from the build's root (geomint_core.dir/__/generated/...)
    string(FIND "${src}" "${CMAKE_CURRENT_SOURCE_DIR}/" in_folder)
    if(in_folder EQUAL 0)
      file(RELATIVE_PATH rel ${CMAKE_CURRENT_SOURCE_DIR} ${src})
    else()
      file(RELATIVE_PATH rel ${CMAKE_BINARY_DIR} ${src})
    endif()
    string(REPLACE "." "\\." pattern "${rel}")
    set(hit ${objects})
    list(FILTER hit INCLUDE REGEX "/${pattern}\\.o$")
    list(LENGTH hit count)
    if(NOT count EQUAL 1)
      message(FATAL_ERROR "${manifest}: no object of ${rel} (the release build there is of another tree?)")
    endif()
    list(APPEND found ${hit})
  endforeach()
  set_source_files_properties(${found} PROPERTIES EXTERNAL_OBJECT TRUE GENERATED TRUE)
  set(${var} ${found} PARENT_SCOPE)
endfunction()

# Units whose speed no figure or benchmark measures, compiled at -O1 in the release build (CI's time is a budget):
# the numeric modified equations (a derivation at a point, or a right-hand side Odeint calls; their
# KnifeEdge unit compiles in 35 s instead of 46 s) and the tests (their time is spent in the library). -O1 and
# -O3 give the same bits here: no fast-math, no contraction (-ffp-contract=off), Eigen's vectorization explicit.
function(geomint_light_unit)
  set_property(SOURCE ${ARGN} APPEND PROPERTY COMPILE_OPTIONS $<$<CONFIG:Release>:-O1>)
endfunction()

# geomint_unpack("a:b:c" X Y Z): X = a, Y = b, Z = c in the caller's scope (an item of the lists above).
macro(geomint_unpack item)
  string(REPLACE ":" ";" _geomint_parts "${item}")
  set(_geomint_index 0)
  foreach(_geomint_var ${ARGN})
    list(GET _geomint_parts ${_geomint_index} ${_geomint_var})
    math(EXPR _geomint_index "${_geomint_index} + 1")
  endforeach()
endmacro()
