# The freestanding libraries: what runs in the box's loop, on Linux and on a microcontroller.
# No heap, no exceptions, no RTTI, no iostream; Eigen fixed-size types only.

# The flags every freestanding library compiles with. EIGEN_NO_MALLOC: any Eigen heap
# allocation aborts (debug builds).
add_library(plinth_freestanding INTERFACE)
target_compile_options(plinth_freestanding INTERFACE
  -fno-exceptions -fno-rtti -fno-threadsafe-statics)
target_compile_definitions(plinth_freestanding INTERFACE EIGEN_NO_MALLOC)

# plinth_freestanding_library(NAME ALIAS SOURCES...): a static library built with those flags,
# and the ctest `<ALIAS>_is_freestanding` that checks with nm that its archive references no
# hosted runtime symbol (tools/check-freestanding.sh).
function(plinth_freestanding_library name alias)
  add_library(${name} STATIC ${ARGN})
  add_library(plinth::${alias} ALIAS ${name})
  target_link_libraries(${name} PRIVATE plinth_freestanding plinth_warnings)
  if(PLINTH_BUILD_TESTS)
    add_test(NAME ${alias}_is_freestanding
      COMMAND ${CMAKE_COMMAND} -E env NM=${CMAKE_NM} NM_TARGET=${PLINTH_NM_TARGET}
              bash ${PROJECT_SOURCE_DIR}/tools/check-freestanding.sh $<TARGET_FILE:${name}>)
  endif()
endfunction()
