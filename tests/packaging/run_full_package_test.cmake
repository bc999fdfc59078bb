# Installs the homcull build tree into a private prefix, then configures, builds and runs the
# consumer of every component (full_consumer) against it, and builds the C99 engine host
# (tests/c_host) against it. Variables: HOMCULL_BUILD_DIR, PACKAGING_DIR, C_HOST_SOURCE_DIR,
# WORK_DIR.
include("${CMAKE_CURRENT_LIST_DIR}/run_step.cmake")
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run_step(${CMAKE_COMMAND} --install "${HOMCULL_BUILD_DIR}" --prefix "${prefix}")
run_step(${CMAKE_COMMAND} -S "${PACKAGING_DIR}/full_consumer" -B "${WORK_DIR}/build" -DCMAKE_PREFIX_PATH=${prefix}
         -DCMAKE_BUILD_TYPE=Release)
run_step(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run_step("${WORK_DIR}/build/consumer" "${WORK_DIR}/city.glb")
run_step(${CMAKE_COMMAND} -S "${C_HOST_SOURCE_DIR}" -B "${WORK_DIR}/c_host" -DCMAKE_PREFIX_PATH=${prefix}
         -DCMAKE_BUILD_TYPE=Release)
run_step(${CMAKE_COMMAND} --build "${WORK_DIR}/c_host")
# Linked with the installed libhomcull.so: it starts, checks the version and asks for its input.
execute_process(COMMAND "${WORK_DIR}/c_host/engine_host" RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 1 OR NOT err MATCHES "usage: engine_host")
  message(FATAL_ERROR "the installed engine host did not run (${code}): ${err}")
endif()
message(STATUS "consumer built and ran against ${prefix}; the C99 engine host built against it")
