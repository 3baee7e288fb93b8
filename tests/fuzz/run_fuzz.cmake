# Configures tests/fuzz as its own project with clang, builds the fuzz
# target, and runs it for SECONDS seconds. Fails on any finding; the input
# that caused it is left in BUILD_DIR/artifacts/.
#   cmake -DSOURCE_DIR=tests/fuzz -DBUILD_DIR=<dir> -DCXX=clang++ -DSECONDS=60 -P run_fuzz.cmake
foreach(var SOURCE_DIR BUILD_DIR CXX SECONDS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzz.cmake: -D${var}=... is required")
  endif()
endforeach()

execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR}
          -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLC_FUZZ=ON
  RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the fuzz build failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target lc_fuzz_scene_loader -j 2
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building lc_fuzz_scene_loader failed")
endif()

# New inputs go to the build tree's corpus (the first folder); the seeds
# and regressions in the source tree are only read. A fixed seed makes a CI
# run repeat the same mutations (up to how many fit in the time); fuzz
# longer with another seed by hand (docs/testing.md).
file(MAKE_DIRECTORY ${BUILD_DIR}/corpus ${BUILD_DIR}/artifacts)
execute_process(
  COMMAND ${BUILD_DIR}/lc_fuzz_scene_loader
          -seed=1 -max_total_time=${SECONDS} -rss_limit_mb=2048 -timeout=10 -print_final_stats=1
          -dict=${SOURCE_DIR}/scene.dict -artifact_prefix=${BUILD_DIR}/artifacts/
          ${BUILD_DIR}/corpus ${SOURCE_DIR}/corpus ${SOURCE_DIR}/regressions
  RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the fuzzer found a problem (exit ${rc}); the input is in ${BUILD_DIR}/artifacts/. "
                      "Keep it under tests/fuzz/regressions/ with the fix (docs/testing.md).")
endif()
