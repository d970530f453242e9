# Writes the simulator's config schema (rtsim-sim --dump-schema) to OUT at build time: the
# Python config tree (python/rtsim/config.py) is made from it, so the package reads the C++
# declaration without importing the C++ extension (and numpy with it).
execute_process(COMMAND ${EXE} --dump-schema OUTPUT_FILE ${OUT} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "rtsim-sim --dump-schema failed (${status})")
endif()
