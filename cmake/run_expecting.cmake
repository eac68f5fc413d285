# Runs a program and passes only when it exits with the expected status (0 unless -DSTATUS=N) AND
# its output matches a regular expression. (CTest's PASS_REGULAR_EXPRESSION alone ignores the exit
# code: a program that prints the expected line and then fails would pass.)
#   cmake -DPROGRAM=path -DEXPECT=regex [-DARGS=a;b] [-DSTATUS=N] -P run_expecting.cmake
if(NOT DEFINED PROGRAM OR NOT DEFINED EXPECT)
  message(FATAL_ERROR "run_expecting.cmake needs -DPROGRAM=... and -DEXPECT=...")
endif()
execute_process(COMMAND "${PROGRAM}" ${ARGS}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
message("${out}")
if(err)
  message("${err}")
endif()
if(NOT DEFINED STATUS)
  set(STATUS 0)
endif()
if(NOT rc STREQUAL "${STATUS}")
  message(FATAL_ERROR "${PROGRAM} exited with ${rc} (expected ${STATUS})")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECT}")
  message(FATAL_ERROR "${PROGRAM}: output does not match '${EXPECT}'")
endif()
