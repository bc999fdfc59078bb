# The core alone, as an engine without the tools' dependencies has it:
# 1. homcull configured and built with Embree, oneTBB, OpenImageIO, assimp and nlohmann_json
#    made unfindable (CMAKE_DISABLE_FIND_PACKAGE_<name>) and truth, io and tbb off, then
#    installed into a private prefix;
# 2. core_consumer: find_package(homcull COMPONENTS core OPTIONAL_COMPONENTS ...) against it,
#    with the same packages unfindable; built and run;
# 3. a project requiring a component that install lacks fails, naming it;
# 4. a C99 program (tests/c_host/engine_host.c) built with pkg-config's flags for homcull
#    against the installed libhomcull.so, and run.
# Variables: HOMCULL_SOURCE_DIR, PACKAGING_DIR, C_HOST_SOURCE, WORK_DIR, C_COMPILER, GENERATOR.
include("${CMAKE_CURRENT_LIST_DIR}/run_step.cmake")
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
set(unfindable "")
foreach(package IN ITEMS embree TBB OpenImageIO assimp nlohmann_json)
  list(APPEND unfindable -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
endforeach()
cmake_host_system_information(RESULT cores QUERY NUMBER_OF_LOGICAL_CORES)

run_step(${CMAKE_COMMAND} -S "${HOMCULL_SOURCE_DIR}" -B "${WORK_DIR}/core" -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
         -DHOMCULL_BUILD_TBB=OFF -DHOMCULL_BUILD_TRUTH=OFF -DHOMCULL_BUILD_IO=OFF -DHOMCULL_BUILD_TOOLS=OFF
         -DHOMCULL_BUILD_TESTS=OFF -DHOMCULL_INSTALL=ON ${unfindable})
run_step(${CMAKE_COMMAND} --build "${WORK_DIR}/core" --parallel ${cores})
run_step(${CMAKE_COMMAND} --install "${WORK_DIR}/core" --prefix "${prefix}")

run_step(${CMAKE_COMMAND} -S "${PACKAGING_DIR}/core_consumer" -B "${WORK_DIR}/consumer" -G "${GENERATOR}"
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${unfindable})
run_step(${CMAKE_COMMAND} --build "${WORK_DIR}/consumer")
run_step("${WORK_DIR}/consumer/core_consumer")

file(WRITE "${WORK_DIR}/needs_truth/CMakeLists.txt"
     "cmake_minimum_required(VERSION 3.20)\nproject(needs_truth LANGUAGES CXX)\nfind_package(homcull 0.2 REQUIRED COMPONENTS truth)\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S "${WORK_DIR}/needs_truth" -B "${WORK_DIR}/needs_truth/build" -DCMAKE_PREFIX_PATH=${prefix}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(code EQUAL 0 OR NOT err MATCHES "truth: this homcull was built without it")
  message(FATAL_ERROR "a required component that is not installed was not refused (${code}):\n${out}\n${err}")
endif()

file(GLOB_RECURSE pc_files "${prefix}/*/homcull.pc")
list(LENGTH pc_files pc_count)
if(NOT pc_count EQUAL 1)
  message(FATAL_ERROR "expected one installed homcull.pc, found: ${pc_files}")
endif()
get_filename_component(pc_dir "${pc_files}" DIRECTORY)
get_filename_component(lib_dir "${pc_dir}" DIRECTORY)
find_program(PKG_CONFIG pkg-config REQUIRED)
execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${pc_dir} ${PKG_CONFIG} --cflags --libs homcull
                RESULT_VARIABLE code OUTPUT_VARIABLE flags ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT code EQUAL 0 OR NOT flags MATCHES "-lhomcull")
  message(FATAL_ERROR "pkg-config --cflags --libs homcull failed (${code}): ${flags} ${err}")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
run_step(${C_COMPILER} -std=c99 -pedantic -Wall -Wextra -Werror -D_POSIX_C_SOURCE=200112L "${C_HOST_SOURCE}" ${flags} -lpthread -lm
         -o "${WORK_DIR}/c_host")
execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${lib_dir} "${WORK_DIR}/c_host" RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 1 OR NOT err MATCHES "usage: engine_host")
  message(FATAL_ERROR "the C99 host built through pkg-config did not run (${code}): ${err}")
endif()
message(STATUS "core-only homcull built and installed without the heavy packages; core consumer and pkg-config C99 host ran")
