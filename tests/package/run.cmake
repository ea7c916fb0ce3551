# ctest's "package" test (CMakeLists.txt): installs the build in GEODE_BUILD_DIR into a fresh
# temporary prefix, builds the downstream project GEODE_PACKAGE_SOURCE against it with
# find_package(geode) and nothing else on the prefix path, and runs it.
set(work ${GEODE_BUILD_DIR}/package-test)
file(REMOVE_RECURSE ${work})
set(prefix ${work}/prefix)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

if(NOT CONFIG)
  set(CONFIG RelWithDebInfo)
endif()
run(${CMAKE_COMMAND} --install ${GEODE_BUILD_DIR} --prefix ${prefix} --config ${CONFIG})
foreach(header include/geode/templates/geode.hpp include/geode/primal/mesh.hpp lib/cmake/geode/geodeConfig.cmake
               lib/cmake/geode/geodeConfigVersion.cmake bin/geode)
  if(NOT EXISTS ${prefix}/${header})
    message(FATAL_ERROR "not installed: ${prefix}/${header}")
  endif()
endforeach()
set(launcher)
if(CMAKE_CXX_COMPILER_LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${CMAKE_CXX_COMPILER_LAUNCHER})
endif()
run(${CMAKE_COMMAND} -S ${GEODE_PACKAGE_SOURCE} -B ${work}/build -DCMAKE_BUILD_TYPE=${CONFIG}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER} ${launcher})
run(${CMAKE_COMMAND} --build ${work}/build)
run(${work}/build/derive_geode)
