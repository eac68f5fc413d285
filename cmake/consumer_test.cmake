# ctest -P script: installs the build tree into a scratch prefix, then builds and runs a consumer
# with find_package(rcb4) from the install and from the build tree, compiles one through pkg-config, checks the installed tool and udev rule,
# and builds a consumer that vendors rcb4 with add_subdirectory.
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed")
endif()
# Configures (with the extra arguments), builds and runs a consumer, which must print the frame.
function(consumer label source build)
  execute_process(COMMAND ${CMAKE_COMMAND} -S ${source} -B ${build} -G Ninja -DCMAKE_CXX_COMPILER=${CXX} ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "configuring the consumer with ${label} failed:\n${out}${err}")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${build} --target consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "building the consumer with ${label} failed:\n${out}${err}")
  endif()
  execute_process(COMMAND ${build}/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "07 0F 00 0A 4C 1D 89")
    message(FATAL_ERROR "the consumer with ${label} ran wrong: ${out}")
  endif()
endfunction()

consumer("find_package(rcb4)" ${SOURCE} ${WORK}/build -DCMAKE_PREFIX_PATH=${WORK}/prefix)
# The build tree as the package, without an install (rcb4_DIR pointing at it).
consumer("rcb4_DIR=the build tree" ${SOURCE} ${WORK}/build-tree -Drcb4_DIR=${BUILD})
find_program(PKG_CONFIG pkg-config REQUIRED)
execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${WORK}/prefix/share/pkgconfig
                        ${PKG_CONFIG} --cflags rcb4 OUTPUT_VARIABLE cflags OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config does not find rcb4")
endif()
separate_arguments(cflags UNIX_COMMAND "${cflags}")
file(WRITE ${WORK}/pc.cpp "#include <rcb4/rcb4.hpp>\nint main() { return rcb4::encode(rcb4::ping{}).size() == 4 ? 0 : 1; }\n")
execute_process(COMMAND ${CXX} ${cflags} ${WORK}/pc.cpp -o ${WORK}/pc RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "compiling with pkg-config --cflags rcb4 failed:\n${err}")
endif()
# The installed command-line tool (when this build has it: examples on) and the udev rule.
if(EXPECT_CLI)
  execute_process(COMMAND ${WORK}/prefix/bin/rcb4 encode servo 0 7500 10 RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "07 0F 00 0A 4C 1D 89")
    message(FATAL_ERROR "the installed rcb4 tool ran wrong (${rc}): ${out}")
  endif()
endif()
if(NOT EXISTS ${WORK}/prefix/lib/udev/rules.d/60-rcb4.rules)
  message(FATAL_ERROR "the udev rule was not installed")
endif()
# A project that vendors rcb4 with add_subdirectory.
consumer("add_subdirectory" ${SOURCE}/../consumer_subdir ${WORK}/subdir -DRCB4_SOURCE=${SOURCE}/../..)
message(STATUS "find_package, pkg-config and add_subdirectory consumers built and ran; the CLI and udev rule installed")
