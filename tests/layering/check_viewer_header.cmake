# renderer.hpp is what a viewer reads and compiles: it must stand alone and reach none of the
# engine's structures, which live behind Renderer's private implementation (tests, tools and
# benchmarks reach them through render/renderer_inspection.hpp). Compiles a translation unit that
# includes only resoct/render/renderer.hpp with -fsyntax-only -H, which lists every header it
# opens, and fails naming each forbidden one and the chain that reached it.
# Input: -DCXX (the compiler), -DINCLUDES (include directories joined by '|'), -DWORK_DIR.

# The engine's vocabulary a viewer names (options, the frame report) without its structures.
set(allowed_engine
    resoct/engine/device_records.hpp resoct/engine/load_failure.hpp
    resoct/engine/request_strategy.hpp resoct/engine/upload_budget.hpp resoct/cache/eviction.hpp)
# Besides every other header of engine/ and cache/, and io/ (the core includes no I/O):
set(forbidden_patterns
    "/resoct/engine/" "/resoct/cache/" "/resoct/io/" "/resoct/render/frame_tables\\.hpp$"
    "/resoct/render/renderer_inspection\\.hpp$"
    # the loader's threads and locks are the implementation's
    "/mutex$" "/thread$" "/condition_variable$" "/shared_mutex$")

file(MAKE_DIRECTORY ${WORK_DIR})
set(tu ${WORK_DIR}/viewer_header.cpp)
file(WRITE ${tu} "#include \"resoct/render/renderer.hpp\"\n")
string(REPLACE "|" ";" include_list "${INCLUDES}")
set(flags -std=c++20 -fsyntax-only -H)
foreach(dir IN LISTS include_list)
  if(dir)
    list(APPEND flags -I${dir})
  endif()
endforeach()
execute_process(COMMAND ${CXX} ${flags} ${tu} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "resoct/render/renderer.hpp does not compile on its own:\n${out}${err}")
endif()

# -H prints one line per opened header: one dot per nesting level, a space, the path.
string(REPLACE "\n" ";" lines "${err}")
set(chain "")
set(bad "")
set(count 0)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^(\\.+) (.+)$")
    continue()
  endif()
  string(LENGTH "${CMAKE_MATCH_1}" depth)
  set(path "${CMAKE_MATCH_2}")
  math(EXPR count "${count} + 1")
  # the chain of includers of this header: the last seen header of each shallower depth
  math(EXPR keep "${depth} - 1")
  list(LENGTH chain n)
  while(n GREATER keep)
    list(POP_BACK chain)
    list(LENGTH chain n)
  endwhile()
  list(APPEND chain "${path}")
  set(allowed FALSE)
  foreach(a IN LISTS allowed_engine)
    string(REPLACE "." "\\." a_re "${a}")
    if(path MATCHES "/${a_re}$")
      set(allowed TRUE)
    endif()
  endforeach()
  if(allowed)
    continue()
  endif()
  foreach(p IN LISTS forbidden_patterns)
    if(path MATCHES "${p}")
      string(JOIN "\n    -> " via ${chain})
      string(APPEND bad "  ${via}\n")
      break()
    endif()
  endforeach()
endforeach()
if(count EQUAL 0)
  message(FATAL_ERROR "${CXX} -H listed no headers; cannot check renderer.hpp:\n${err}")
endif()
if(bad)
  message(FATAL_ERROR
          "resoct/render/renderer.hpp reaches headers a viewer must not need (engine structures, "
          "I/O, threads and locks; move what the viewer API names into a small vocabulary header "
          "of its layer, and what only tests and tools use into render/renderer_inspection.hpp):\n"
          "${bad}")
endif()
message(STATUS "renderer.hpp opens ${count} headers, none of the engine's structures")
