# rcb4_warnings(target): the project's warning set (GCC 12 and Clang), errors when asked.
function(rcb4_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion
    -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual
    -Wdouble-promotion -Wimplicit-fallthrough)
  if(RCB4_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
    # GCC 12 at -O2/-O3 reports -Wstringop-overflow / -Wrestrict inside std::string and after
    # store merging in code whose bounds are checked (GCC bugs 105329, 106199). They stay
    # warnings there; the dev build (-O0, -Werror), ASan and the fuzzers check these paths.
    target_compile_options(${target} PRIVATE
      $<$<AND:$<CXX_COMPILER_ID:GNU>,$<NOT:$<CONFIG:Debug>>>:-Wno-error=stringop-overflow;-Wno-error=restrict>)
  endif()
endfunction()
