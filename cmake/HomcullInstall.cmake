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

# homcull.pc: the C interface's shared library for pkg-config. Relocatable: the prefix is
# found from the file's own place (${pcfiledir}), so an install with --prefix works as is.
if(TARGET homcull_shared)
  file(RELATIVE_PATH HOMCULL_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
  string(REGEX REPLACE "/$" "" HOMCULL_PC_TO_PREFIX "${HOMCULL_PC_TO_PREFIX}")
  configure_file(cmake/homcull.pc.in "${PROJECT_BINARY_DIR}/homcull.pc" @ONLY)
  install(FILES "${PROJECT_BINARY_DIR}/homcull.pc" DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()
