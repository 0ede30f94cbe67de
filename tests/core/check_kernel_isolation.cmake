# Checks that the variants of the vectorised kernel compiled for wider instruction sets
# than the build's (AVX2, AVX-512: src/CMakeLists.txt) define no symbol that any other
# object file of the program defines too. Such a symbol (an inline function or template
# instantiation, emitted weak in every object that uses it) would be kept once for the
# whole program, possibly the AVX-512 copy, and then run on processors without AVX-512.
#
#   cmake -DNM=nm -DOBJECTS_FILE=kernel_objects.cmake -P check_kernel_isolation.cmake
#
# OBJECTS_FILE sets WIDE (the object files of the wide variants) and OTHERS (every other
# object file of the superball program); tests/CMakeLists.txt generates it.
include(${OBJECTS_FILE})

function(defined_symbols object out)
  execute_process(COMMAND ${NM} --defined-only --extern-only --format=posix ${object}
                  OUTPUT_VARIABLE text RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${object}")
  endif()
  string(REGEX MATCHALL "[^\n]+" lines "${text}")
  set(names)
  foreach(line ${lines})
    string(REGEX REPLACE " .*" "" name "${line}")
    # The pointer to the C++ personality routine: data, the same in every object.
    if(NOT name MATCHES "^DW\\.ref\\.")
      list(APPEND names ${name})
    endif()
  endforeach()
  set(${out} ${names} PARENT_SCOPE)
endfunction()

if(NOT WIDE)
  message(STATUS "no variant compiled for a wider instruction set than the build's: nothing to check")
  return()
endif()

set(everything ${WIDE} ${OTHERS})
foreach(object ${everything})
  defined_symbols(${object} symbols_${object})
endforeach()

set(clashes 0)
foreach(wide ${WIDE})
  list(LENGTH symbols_${wide} count)
  if(count EQUAL 0)
    message(SEND_ERROR "${wide} defines no symbol: not a kernel variant")
    math(EXPR clashes "${clashes} + 1")
  endif()
  foreach(other ${everything})
    if(other STREQUAL wide)
      continue()
    endif()
    foreach(name ${symbols_${wide}})
      list(FIND symbols_${other} ${name} at)
      if(at GREATER -1)
        message(SEND_ERROR "${name} is defined by ${wide} and by ${other}")
        math(EXPR clashes "${clashes} + 1")
      endif()
    endforeach()
  endforeach()
  message(STATUS "${wide}: ${count} symbols checked")
endforeach()
if(clashes GREATER 0)
  message(FATAL_ERROR "${clashes} symbols of wide kernel variants are defined elsewhere too")
endif()
