# cmake -DTB=<testbench> -DARGS="<plusargs>" -DEXPECT="<text>" -P expect_named_mismatch.cmake
# The scoreboard testbench run with an output bit inverted must fail (non-zero exit) and print
# exactly one MISMATCH line, the one that starts with EXPECT (the unit, the vector, the field).
separate_arguments(_args UNIX_COMMAND "${ARGS}")
execute_process(COMMAND ${TB} ${_args} OUTPUT_VARIABLE _out ERROR_VARIABLE _err
                RESULT_VARIABLE _rc)
message("${_out}${_err}")
if("${_rc}" STREQUAL "0")
  message(FATAL_ERROR "the testbench passed with ${ARGS}")
endif()
string(REGEX MATCHALL "MISMATCH[^\n]*" _lines "${_out}")
list(LENGTH _lines _n)
if(NOT _n EQUAL 1)
  message(FATAL_ERROR "${_n} MISMATCH lines, expected one")
endif()
string(FIND "${_lines}" "${EXPECT}" _at)
if(NOT _at EQUAL 0)
  message(FATAL_ERROR "the MISMATCH line does not start with '${EXPECT}'")
endif()
