# Install rules and a versioned package config, so that consumers can write
#   find_package(homcull 0.2 REQUIRED COMPONENTS truth io)
#   target_link_libraries(app PRIVATE homcull::core homcull::truth)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(HOMCULL_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/homcull")
install(TARGETS homcull_core homcull_shared homcull_tbb homcull_truth homcull_io EXPORT homcullTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY lib/include/homcull DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET homcull_cli)
  install(TARGETS homcull_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(EXPORT homcullTargets NAMESPACE homcull:: DESTINATION ${HOMCULL_CMAKE_DIR})
configure_package_config_file(cmake/homcullConfig.cmake.in
    "${PROJECT_BINARY_DIR}/homcullConfig.cmake" INSTALL_DESTINATION ${HOMCULL_CMAKE_DIR})
write_basic_package_version_file("${PROJECT_BINARY_DIR}/homcullConfigVersion.cmake"
    COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/homcullConfig.cmake"
              "${PROJECT_BINARY_DIR}/homcullConfigVersion.cmake"
        DESTINATION ${HOMCULL_CMAKE_DIR})
