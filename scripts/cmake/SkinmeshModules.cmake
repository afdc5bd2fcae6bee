# How a skinmesh library module is declared: one static library per module,
# skinmesh_<name>, aliased skinmesh::<name>, with its public headers under
# <module>/include/skinmesh/<name>/, the project's warnings, and installed
# and exported as skinmesh::<name>.

# The same warnings for every target of the project (libraries, the command,
# tests, benchmarks).
function(skinmesh_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
endfunction()

# skinmesh_add_module(NAME SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
function(skinmesh_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target skinmesh_${name})
  add_library(${target} ${ARG_SOURCES})
  add_library(skinmesh::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  target_compile_features(${target} PUBLIC cxx_std_17)
  skinmesh_warnings(${target})
  if(SKINMESH_INSTALL)
    install(TARGETS ${target} EXPORT skinmeshTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
    install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endfunction()
