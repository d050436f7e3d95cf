# Packaging check, run by ctest: install resoct into a fresh prefix, then configure, build and run
# examples/from_install against (1) the install tree and (2) the build tree.
# Both consumers also build the viewer API examples (examples/NN_*.cpp) and run 02, the README's
# C++ snippet. With -DPYTHON, the README's Python snippet (examples/python/render_frame.py) runs
# with the module installed into <prefix>/PYTHON_DIR.
# Inputs: -DSOURCE_DIR -DBINARY_DIR -DWORK_DIR -DCOMPONENTS (semicolon list, e.g. "io;cpu;vulkan"),
# optionally -DPYTHON (interpreter) -DPYTHON_DIR (module directory below the prefix), and
# -DCONSUMER_CXX_COMPILER and -DCONSUMER_CXX_FLAGS, resoct's own, for the consumer.
foreach(v SOURCE_DIR BINARY_DIR WORK_DIR COMPONENTS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check_package.cmake: -D${v}= is required")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${prefix})
foreach(f include/resoct/volume/hierarchy.hpp include/resoct/version.hpp
          include/resoct/io/open_source.hpp include/resoct/kernel/layout_version.glsl.h
          lib/cmake/resoct/resoctConfig.cmake lib/cmake/resoct/resoctConfigVersion.cmake
          lib/cmake/resoct/resoct-core-targets.cmake lib/cmake/resoct/resoct-io-targets.cmake)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "install tree lacks ${f}")
  endif()
endforeach()

# The command-line tools install beside each other (resoct-view where GLFW was found).
if(EXPECT_TOOLS)
  set(tools resoct-render resoct-convert resoct-info)
  if(EXPECT_VIEWER)
    list(APPEND tools resoct-view)
  endif()
  foreach(t IN LISTS tools)
    if(NOT EXISTS ${prefix}/bin/${t})
      message(FATAL_ERROR "install tree lacks bin/${t}")
    endif()
  endforeach()
endif()

string(REPLACE ";" "\\;" comps "${COMPONENTS}")
set(toolchain)
if(CONSUMER_CXX_COMPILER)
  list(APPEND toolchain -DCMAKE_CXX_COMPILER=${CONSUMER_CXX_COMPILER})
endif()
if(CONSUMER_CXX_FLAGS)
  list(APPEND toolchain "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}")
endif()
foreach(kind install build)
  if(kind STREQUAL "install")
    set(locate -DCMAKE_PREFIX_PATH=${prefix})
  else()
    set(locate -Dresoct_DIR=${BINARY_DIR})
  endif()
  set(bdir ${WORK_DIR}/consumer-${kind})
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/from_install -B ${bdir} -G Ninja
      -DCMAKE_BUILD_TYPE=Release ${locate} "-DRESOCT_CONSUMER_COMPONENTS=${comps}"
      -DRESOCT_API_EXAMPLES_DIR=${SOURCE_DIR}/examples ${toolchain})
  run(${CMAKE_COMMAND} --build ${bdir})
  run(${bdir}/consumer)
  execute_process(COMMAND ${bdir}/example_02_render_frame
                  WORKING_DIRECTORY ${bdir} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${bdir}/frame.png)
    message(FATAL_ERROR "examples/02_render_frame against the ${kind} tree failed (${rc}):\n"
                        "${out}\n${err}")
  endif()
  message(STATUS "consumer against the ${kind} tree: ok")
endforeach()

# A component that was not built must make find_package fail, not silently succeed.
set(bdir ${WORK_DIR}/consumer-missing)
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/from_install -B ${bdir} -G Ninja
                -DCMAKE_PREFIX_PATH=${prefix} -DRESOCT_CONSUMER_COMPONENTS=io\;cpu\;nonexistent
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
if(rc EQUAL 0)
  message(FATAL_ERROR "find_package succeeded with a nonexistent component")
endif()

if(PYTHON)
  # Run where nothing of the build tree is importable: only the installed module can be found.
  set(pydir ${WORK_DIR}/python-snippet)
  file(MAKE_DIRECTORY ${pydir})
  set(env ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_DIR})
  run(${env} ${PYTHON} -c
      "import resoct, sys; sys.exit(0 if resoct.__file__.startswith('${prefix}/') else 1)")
  execute_process(COMMAND ${env} ${PYTHON} ${SOURCE_DIR}/examples/python/render_frame.py
                  WORKING_DIRECTORY ${pydir} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${pydir}/frame.png)
    message(FATAL_ERROR "examples/python/render_frame.py with the installed module failed "
                        "(${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "README Python example against the install tree: ok (${out})")
endif()
