# `fieldguard replay --workers 1` and `--workers 4` give byte-identical output on a fused recording: the
# simulator's uneven-drive session (3D LiDAR pcap, 2D LiDAR, GNSS and AHRS byte logs) through sync, geo
# compensation, perception and the safety monitor, on one and on four worker threads. Run by CTest in every
# build; in the ThreadSanitizer build (tools/test) it is the threaded pipeline's end-to-end race check.
# -DSIM=fieldguard-sim -DFIELDGUARD=fieldguard -DCONFIG=yaml -DWORK=dir [-DROTATIONS=n]
foreach(v SIM FIELDGUARD CONFIG WORK)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "ReplayWorkersIdentical: -D${v}=... is required")
  endif()
endforeach()
if(NOT DEFINED ROTATIONS)
  set(ROTATIONS 50)
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
execute_process(COMMAND "${SIM}" --scene uneven-drive --session "${WORK}/s" --rotations ${ROTATIONS} --seed 2 --quiet
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fieldguard-sim failed (${rc}): ${err}")
endif()
foreach(w 1 4)
  execute_process(COMMAND "${FIELDGUARD}" replay --config "${CONFIG}" --session "${WORK}/s" --workers ${w} --quiet
                          --obstacles-out "${WORK}/obstacles_${w}.jsonl" --can-log "${WORK}/can_${w}.log"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "replay --workers ${w} failed (${rc}):\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "workers           ${w}, 0 frames lost")
    message(FATAL_ERROR "replay --workers ${w} lost frames:\n${out}")
  endif()
endforeach()
file(STRINGS "${WORK}/obstacles_1.jsonl" lines)
list(LENGTH lines n)
math(EXPR expected "${ROTATIONS} / 2 - 2")
if(n LESS expected)
  message(FATAL_ERROR "only ${n} frames in ${WORK}/obstacles_1.jsonl, expected at least ${expected}")
endif()
list(GET lines 5 sample)
if(NOT sample MATCHES "\"levelling\":\"full\"")
  message(FATAL_ERROR "frame 5 is not a fused, levelled frame: ${sample}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${WORK}/obstacles_1.jsonl" "${WORK}/obstacles_4.jsonl"
                RESULT_VARIABLE d1)
execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${WORK}/can_1.log" "${WORK}/can_4.log" RESULT_VARIABLE d2)
if(NOT d1 EQUAL 0 OR NOT d2 EQUAL 0)
  message(FATAL_ERROR "--workers 1 and --workers 4 differ (obstacles: ${d1}, CAN log: ${d2}); see ${WORK}")
endif()
message(STATUS "${n} fused frames, obstacles and CAN log byte-identical with 1 and 4 workers")
file(REMOVE_RECURSE "${WORK}")
