# Configures tests/fuzz as its own project with clang, builds one fuzz
# target, and runs it on RUNS inputs. Fails on any finding; the input that
# caused it is left in BUILD_DIR/runs/TARGET/artifacts/.
#   cmake -DSOURCE_DIR=tests/fuzz -DBUILD_DIR=<dir> -DCXX=clang++ -DRUNS=50000 \
#         [-DTARGET=lc_fuzz_scene_loader -DDICT=scene.dict -DCORPUS=corpus -DREGRESSIONS=regressions] \
#         -P run_fuzz.cmake
foreach(var SOURCE_DIR BUILD_DIR CXX RUNS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzz.cmake: -D${var}=... is required")
  endif()
endforeach()
if(NOT DEFINED TARGET)
  set(TARGET lc_fuzz_scene_loader)
  set(DICT scene.dict)
  set(CORPUS corpus)
  set(REGRESSIONS regressions)
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR}
          -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLC_FUZZ=ON
  RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the fuzz build failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET} -j 2
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building ${TARGET} failed")
endif()

# New inputs go to the build tree's corpus (the first folder); the seeds
# and regressions in the source tree are only read. A fixed seed and a
# fixed number of runs make a CI run (which starts from an empty build
# corpus) try the same inputs whatever the machine's speed; fuzz longer with
# another seed by hand (docs/testing.md).
set(work ${BUILD_DIR}/runs/${TARGET})
file(MAKE_DIRECTORY ${work}/corpus ${work}/artifacts)
execute_process(
  COMMAND ${BUILD_DIR}/${TARGET}
          -seed=1 -runs=${RUNS} -rss_limit_mb=2048 -timeout=10 -print_final_stats=1
          -dict=${SOURCE_DIR}/${DICT} -artifact_prefix=${work}/artifacts/
          ${work}/corpus ${SOURCE_DIR}/${CORPUS} ${SOURCE_DIR}/${REGRESSIONS}
  RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "the fuzzer found a problem (exit ${rc}); the input is in ${work}/artifacts/. "
                      "Keep it under tests/fuzz/${REGRESSIONS}/ with the fix (docs/testing.md).")
endif()
