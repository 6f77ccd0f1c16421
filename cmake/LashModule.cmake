# lash_module(NAME [SOURCES file...] [USES module...] [PUBLIC_LIBS lib...] [PRIVATE_LIBS lib...])
#
# One library per module of DESIGN.md: target lash_NAME (alias lash::NAME, exported as
# lash::NAME), sources from src/NAME/ only, linking only the lash modules in USES, each of
# which cmake/layers.txt must allow (same level or below). A module without sources is an
# INTERFACE library. Every module is added to lash::lash and to the install export.
#
# Adding a module (e.g. metrics): write src/metrics/CMakeLists.txt with
#   lash_module(metrics SOURCES nrmse.cpp USES io)
# add `add_subdirectory(metrics)` to src/CMakeLists.txt (below the modules it uses), and
# name it in the USES of every module that includes its headers. The layer test
# (scripts/check_layers.py) then checks its #includes against cmake/layers.txt and USES.

set(_lash_level 0)
file(STRINGS ${PROJECT_SOURCE_DIR}/cmake/layers.txt _lash_layer_lines REGEX "^[a-z]")
foreach(_line IN LISTS _lash_layer_lines)
  if(_line MATCHES "^only ([a-z_]+): *(.*)$")
    string(REPLACE " " ";" _only "${CMAKE_MATCH_2}")
    set_property(GLOBAL PROPERTY LASH_ONLY_${CMAKE_MATCH_1} "${_only}")
  elseif(_line MATCHES "^[a-z]+: *(.*)$")
    math(EXPR _lash_level "${_lash_level} + 1")
    string(REPLACE " " ";" _mods "${CMAKE_MATCH_1}")
    foreach(_m IN LISTS _mods)
      set_property(GLOBAL PROPERTY LASH_LEVEL_${_m} ${_lash_level})
    endforeach()
  endif()
endforeach()

function(lash_module name)
  cmake_parse_arguments(M "" "" "SOURCES;USES;PUBLIC_LIBS;PRIVATE_LIBS" ${ARGN})
  get_property(level GLOBAL PROPERTY LASH_LEVEL_${name})
  if(NOT level)
    message(FATAL_ERROR "lash_module(${name}): not a module of cmake/layers.txt")
  endif()
  get_property(only GLOBAL PROPERTY LASH_ONLY_${name})
  foreach(u IN LISTS M_USES)
    get_property(ul GLOBAL PROPERTY LASH_LEVEL_${u})
    if(NOT ul OR ul GREATER level OR (only AND NOT u IN_LIST only))
      message(FATAL_ERROR "lash_module(${name}): may not use '${u}' (cmake/layers.txt)")
    endif()
    if(NOT TARGET lash_${u})
      message(FATAL_ERROR "lash_module(${name}): module '${u}' must be added before it")
    endif()
  endforeach()
  foreach(s IN LISTS M_SOURCES)
    get_filename_component(abs ${s} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    if(NOT abs MATCHES "^${PROJECT_SOURCE_DIR}/src/${name}/")
      message(FATAL_ERROR "lash_module(${name}): ${s} is not under src/${name}/ (a module compiles only its own sources)")
    endif()
  endforeach()
  set(tgt lash_${name})
  list(TRANSFORM M_USES PREPEND lash_ OUTPUT_VARIABLE deps)
  if(M_SOURCES)
    add_library(${tgt} ${M_SOURCES})
    set(scope PUBLIC)
    target_link_libraries(${tgt} PRIVATE lash_options ${M_PRIVATE_LIBS})
  else()
    add_library(${tgt} INTERFACE)
    set(scope INTERFACE)
  endif()
  add_library(lash::${name} ALIAS ${tgt})
  set_target_properties(${tgt} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${tgt} ${scope}
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_features(${tgt} ${scope} cxx_std_20)
  target_link_libraries(${tgt} ${scope} ${deps} ${M_PUBLIC_LIBS})
  set_property(GLOBAL APPEND PROPERTY LASH_MODULES ${name})
  set_property(GLOBAL PROPERTY LASH_USES_${name} "${M_USES}")
  set_property(GLOBAL PROPERTY LASH_DIR_${name} "${CMAKE_CURRENT_SOURCE_DIR}")
endfunction()
