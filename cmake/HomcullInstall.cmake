# Install rules, a versioned package config with components, and homcull.pc, so that consumers
# can write
#   find_package(homcull 0.2 REQUIRED COMPONENTS core)            # homcull::core, homcull::shared
#   find_package(homcull 0.2 REQUIRED COMPONENTS core truth io)   # and the tools' libraries
#   pkg-config --cflags --libs homcull                            # C: libhomcull.so
# Each component is an export set of its own, and the package config finds only the
# dependencies of the components asked for (cmake/homcullConfig.cmake.in).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(HOMCULL_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/homcull")
install(DIRECTORY lib/include/homcull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# component -> its targets (those this build has)
set(_homcull_component_targets_core homcull_core)
if(TARGET homcull_shared)
  list(APPEND _homcull_component_targets_core homcull_shared)
endif()
set(_homcull_component_targets_tbb homcull_tbb)
set(_homcull_component_targets_truth homcull_truth)
set(_homcull_component_targets_io homcull_io)
foreach(component IN ITEMS core tbb truth io)
  list(GET _homcull_component_targets_${component} 0 _first)
  if(NOT TARGET ${_first})
    continue()  # not built: the package config says so when it is asked for
  endif()
  install(TARGETS ${_homcull_component_targets_${component}} EXPORT homcull_${component}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT homcull_${component} NAMESPACE homcull:: FILE homcull_${component}Targets.cmake DESTINATION ${HOMCULL_CMAKE_DIR})
endforeach()
if(TARGET homcull_oiio)
  # Not linked by anyone: homcull::io loads it (lib/io/image_backend.hpp).
  install(TARGETS homcull_oiio LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/homcull)
endif()
if(TARGET homcull_cli)
  install(TARGETS homcull_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

configure_package_config_file(cmake/homcullConfig.cmake.in
    "${PROJECT_BINARY_DIR}/homcullConfig.cmake" INSTALL_DESTINATION ${HOMCULL_CMAKE_DIR})
write_basic_package_version_file("${PROJECT_BINARY_DIR}/homcullConfigVersion.cmake"
    COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/homcullConfig.cmake"
              "${PROJECT_BINARY_DIR}/homcullConfigVersion.cmake"
        DESTINATION ${HOMCULL_CMAKE_DIR})

# homcull.pc: the C interface's shared library for pkg-config. With the usual relative folders
# it is relocatable: the prefix is found from the file's own place (${pcfiledir}), so an install
# with --prefix works as is. GNUInstallDirs also allows absolute folders
# (-DCMAKE_INSTALL_LIBDIR=/opt/lib64): those are written as they are, and with an absolute
# libdir the prefix (for a relative includedir) is the one installed to, written at install time.
if(TARGET homcull_shared)
  foreach(dir IN ITEMS LIBDIR INCLUDEDIR)
    if(IS_ABSOLUTE "${CMAKE_INSTALL_${dir}}")
      set(HOMCULL_PC_${dir} "${CMAKE_INSTALL_${dir}}")
    else()
      set(HOMCULL_PC_${dir} "\${prefix}/${CMAKE_INSTALL_${dir}}")
    endif()
  endforeach()
  if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
    # Bracket arguments: the values (a relative includedir is "${prefix}/include") are written
    # into the install script as they are, not expanded when it runs.
    install(CODE "
      set(HOMCULL_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\")
      set(HOMCULL_PC_LIBDIR [==[${HOMCULL_PC_LIBDIR}]==])
      set(HOMCULL_PC_INCLUDEDIR [==[${HOMCULL_PC_INCLUDEDIR}]==])
      set(PROJECT_DESCRIPTION [==[${PROJECT_DESCRIPTION}]==])
      set(PROJECT_VERSION [==[${PROJECT_VERSION}]==])
      configure_file([==[${PROJECT_SOURCE_DIR}/cmake/homcull.pc.in]==] [==[${PROJECT_BINARY_DIR}/homcull.pc]==] @ONLY)")
  else()
    file(RELATIVE_PATH HOMCULL_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
    string(REGEX REPLACE "/$" "" HOMCULL_PC_TO_PREFIX "${HOMCULL_PC_TO_PREFIX}")
    set(HOMCULL_PC_PREFIX "\${pcfiledir}/${HOMCULL_PC_TO_PREFIX}")
    configure_file(cmake/homcull.pc.in "${PROJECT_BINARY_DIR}/homcull.pc" @ONLY)
  endif()
  install(FILES "${PROJECT_BINARY_DIR}/homcull.pc" DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()
