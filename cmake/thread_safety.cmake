# COSMIC_THREAD_SAFETY: clang's thread safety analysis over every target, its findings errors
# (cosmic/thread_annotations.hpp says what is annotated; scripts/test builds it in build-tsa).
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "COSMIC_THREAD_SAFETY needs clang (CC=clang CXX=clang++): "
                      "${CMAKE_CXX_COMPILER_ID} has no thread safety analysis")
endif()
# -Wthread-safety-beta: the checks clang 14 still marks beta; the code is clean under them too.
set(COSMIC_THREAD_SAFETY_FLAGS -Wthread-safety -Wthread-safety-beta -Werror=thread-safety -Werror=thread-safety-beta)
add_compile_options("$<$<COMPILE_LANGUAGE:CXX>:${COSMIC_THREAD_SAFETY_FLAGS}>")

# The analysis must be live: a read of a guarded member without its mutex must not compile, and
# the same file with the lock taken must. Otherwise (flags dropped, macros expanding to nothing,
# the wrappers losing their annotations) the stage would pass while checking nothing.
set(_tsa_probe ${PROJECT_SOURCE_DIR}/tests/thread_safety/unguarded_read.cpp)
set(_tsa_includes "${PROJECT_SOURCE_DIR}/lib/core/include;${PROJECT_SOURCE_DIR}/lib/router/include")
try_compile(_tsa_locked_compiles ${CMAKE_BINARY_DIR}/thread_safety_probe/locked ${_tsa_probe}
  CMAKE_FLAGS "-DINCLUDE_DIRECTORIES=${_tsa_includes}"
  COMPILE_DEFINITIONS ${COSMIC_THREAD_SAFETY_FLAGS} -DCOSMIC_TSA_LOCKED
  CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON
  OUTPUT_VARIABLE _tsa_locked_output)
if(NOT _tsa_locked_compiles)
  message(FATAL_ERROR "thread-safety probe: ${_tsa_probe} with the lock taken does not compile:\n${_tsa_locked_output}")
endif()
try_compile(_tsa_unguarded_compiles ${CMAKE_BINARY_DIR}/thread_safety_probe/unguarded ${_tsa_probe}
  CMAKE_FLAGS "-DINCLUDE_DIRECTORIES=${_tsa_includes}"
  COMPILE_DEFINITIONS ${COSMIC_THREAD_SAFETY_FLAGS}
  CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON
  OUTPUT_VARIABLE _tsa_unguarded_output)
if(_tsa_unguarded_compiles OR NOT _tsa_unguarded_output MATCHES "requires holding mutex 'mutex_'")
  message(FATAL_ERROR "thread-safety probe: ${_tsa_probe} reads a guarded member without its mutex "
                      "and was not refused by the analysis: -Wthread-safety is not live\n${_tsa_unguarded_output}")
endif()
list(JOIN COSMIC_THREAD_SAFETY_FLAGS " " _tsa_shown)
message(STATUS "Thread safety analysis: on (${_tsa_shown}); its probe was refused, as it must be")
