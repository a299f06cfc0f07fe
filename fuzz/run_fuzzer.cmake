# ctest driver for one fuzz target: seeds the corpus folder from SEEDS (files of the right kind
# only), then runs the fuzzer for SECONDS on one core. A crash, leak or sanitizer report makes
# libFuzzer exit non-zero and the test fail; the reproducer is left as crash-* in the build folder.
file(MAKE_DIRECTORY ${CORPUS})
foreach(dir ${SEEDS})
  file(GLOB_RECURSE seeds "${dir}/*.json" "${dir}/*.csv" "${dir}/*.ply" "${dir}/*.obj"
                            "${dir}/*.dng" "${dir}/*.lut" "${dir}/*.exr" "${dir}/*.png")
  foreach(seed ${seeds})
    file(SIZE ${seed} bytes)
    if(bytes LESS 1048576)
      file(COPY ${seed} DESTINATION ${CORPUS})
    endif()
  endforeach()
endforeach()
execute_process(COMMAND ${FUZZER} -max_total_time=${SECONDS} -max_len=65536 -timeout=20
                        -rss_limit_mb=2048 -print_final_stats=1 ${CORPUS}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${FUZZER} found a problem (exit ${rc}); see crash-* beside it")
endif()
