# Writes what the simulator declares (rtsim-sim FLAG: --dump-schema, --dump-names) to OUT at
# build time: the Python config tree (python/rtsim/config.py) and names (python/rtsim/kinds.py)
# are made from them, so the package reads the C++ declarations without importing the C++
# extension (and numpy with it).
if(NOT FLAG)
  set(FLAG --dump-schema)
endif()
execute_process(COMMAND ${EXE} ${FLAG} OUTPUT_FILE ${OUT} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "rtsim-sim ${FLAG} failed (${status})")
endif()
