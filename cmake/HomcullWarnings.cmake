# homcull_set_warnings(target): the project's warning set, applied to its own targets only.
function(homcull_set_warnings target)
  if(MSVC)
    target_compile_options(${target} PRIVATE /W4)
    if(HOMCULL_WARNINGS_AS_ERRORS)
      target_compile_options(${target} PRIVATE /WX)
    endif()
  else()
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow
                           -Wnon-virtual-dtor -Wcast-align -Wunused
                           -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
    if(HOMCULL_WARNINGS_AS_ERRORS)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()
