# homcull_set_warnings(target): the project's settings for one of its own targets: its warning
# set, and -O3 in optimised builds (CMake's Release default is -O3 already; RelWithDebInfo's is
# -O2). On the target only, never through global flags, so that a parent project's own targets
# keep the flags it chose.
function(homcull_set_warnings target)
  if(MSVC)
    target_compile_options(${target} PRIVATE /W4)
    if(HOMCULL_WARNINGS_AS_ERRORS)
      target_compile_options(${target} PRIVATE /WX)
    endif()
  else()
    target_compile_options(${target} PRIVATE $<$<CONFIG:Release,RelWithDebInfo>:-O3>)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                           -Wnon-virtual-dtor -Wcast-align -Wunused
                           -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
    if(HOMCULL_WARNINGS_AS_ERRORS)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()
