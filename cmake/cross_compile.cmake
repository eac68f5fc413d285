# ctest -P script: compiles SOURCE for a Cortex-M4 with arm-none-eabi-g++ (exit 77 = skipped when absent).
find_program(ARM_CXX arm-none-eabi-g++)
if(NOT ARM_CXX)
  message("SKIPPED: arm-none-eabi-g++ not found; run cmake/install-deps.sh to get gcc-arm-none-eabi")
  # ctest maps this code to "skipped" through SKIP_RETURN_CODE
  cmake_language(EXIT 77)
endif()
execute_process(COMMAND ${ARM_CXX} -std=c++20 -mcpu=cortex-m4 -mthumb -fno-exceptions -fno-rtti -Os
  -Wall -Wextra -Wpedantic -Wconversion -Werror -I${INCLUDE} -c ${SOURCE} -o ${OUTPUT}
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "Cortex-M4 build of the codec failed:\n${err}")
endif()
execute_process(COMMAND arm-none-eabi-size ${OUTPUT} OUTPUT_VARIABLE size)
message(STATUS "Cortex-M4 object built:\n${size}")
