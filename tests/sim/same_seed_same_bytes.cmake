# Script mode: runs the simulator tool twice with the same seed (1 and 2
# worker threads) and requires byte-identical outputs; then reads every bag
# back with swarmlio_bag_info (ROS1 bags, or MCAP files with
# --bag_format=mcap). EXTRA_ARGS (optional): more simulator flags.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()
file(REMOVE_RECURSE ${WORK_DIR})
foreach(threads 1 2)
  run(${SIM} --scenario ${SCENARIO} --output_dir ${WORK_DIR}/run${threads} --duration_s 1.5
      --threads ${threads} ${EXTRA_ARGS})
endforeach()
# The resolved scenario records the thread count, so only the sensor logs and
# ground truth are compared.
file(GLOB files RELATIVE ${WORK_DIR}/run1 ${WORK_DIR}/run1/*.bag ${WORK_DIR}/run1/*.mcap
     ${WORK_DIR}/run1/*.txt)
list(LENGTH files count)
if(count LESS 6)
  message(FATAL_ERROR "expected 3 bags and 3 TUM files, got: ${files}")
endif()
foreach(f ${files})
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK_DIR}/run1/${f} ${WORK_DIR}/run2/${f}
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "${f} differs between two runs with the same seed")
  endif()
endforeach()
file(GLOB bags ${WORK_DIR}/run1/*.bag ${WORK_DIR}/run1/*.mcap)
foreach(b ${bags})
  run(${BAG_INFO} ${b})
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
message(STATUS "identical: ${files}")
