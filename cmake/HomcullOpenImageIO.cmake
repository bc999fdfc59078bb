# find_package(OpenImageIO), then repair Debian 12's imported target: its
# INTERFACE_INCLUDE_DIRECTORIES names /usr/include/opencv4, which only exists when the
# (large, otherwise unneeded) libopencv-dev is installed, and CMake refuses missing paths.
find_package(OpenImageIO REQUIRED)
if(TARGET OpenImageIO::OpenImageIO)
  get_target_property(_homcull_oiio_includes OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
  if(_homcull_oiio_includes)
    set(_homcull_existing "")
    foreach(_dir IN LISTS _homcull_oiio_includes)
      if(EXISTS "${_dir}" OR _dir MATCHES "^\\$<")
        list(APPEND _homcull_existing "${_dir}")
      endif()
    endforeach()
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_homcull_existing}")
  endif()
endif()
