# One smoke run of a libFuzzer harness (CTest, label "fuzz"): cmake -DFUZZER=... -DSCRATCH=...
# -DSEEDS=dir[;dir...] -DOPTIONS=opt[;opt...] -P run_smoke.cmake. A fresh scratch corpus takes
# the inputs libFuzzer finds (the committed seeds in SEEDS are only read); artifacts of a crash land in
# SCRATCH/artifacts/. Fails when the harness exits non-zero (crash, sanitizer report, leak,
# timeout, out of memory).
foreach(variable FUZZER SCRATCH SEEDS OPTIONS)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "run_smoke.cmake: ${variable} is not set")
  endif()
endforeach()
file(REMOVE_RECURSE ${SCRATCH}/corpus)
file(MAKE_DIRECTORY ${SCRATCH}/corpus ${SCRATCH}/artifacts)
execute_process(
  COMMAND ${FUZZER} ${OPTIONS} -artifact_prefix=${SCRATCH}/artifacts/ ${SCRATCH}/corpus ${SEEDS}
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "${FUZZER} failed (exit ${result}); crash artifacts, if any, are in "
                      "${SCRATCH}/artifacts/")
endif()
