# The layer order of docs/architecture.md §1.0: a layer folder includes only the folders listed
# before it, so the core (everything outside io/) never includes I/O, and the backends include
# the core only. Reads every file of the layer folders under include/resoct/ and src/core/ and of
# the backends (include/resoct/{cpu,vulkan}, src/backend_*), and fails naming each #include of a
# later layer (as "resoct/<layer>/..." or, inside src/, by layer path "<layer>/...").
# Input: -DSOURCE_DIR.

# Bottom up; the kernel headers are below all of them.
set(layers kernel base volume sources cache scene engine backend render io)

function(check_file file own_rank rule)
  file(STRINGS ${file} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  foreach(line IN LISTS includes)
    if(NOT line MATCHES "include[ \t]*[<\"](resoct/)?([a-z_]+)/")
      continue()
    endif()
    list(FIND layers "${CMAKE_MATCH_2}" rank)
    if(rank GREATER own_rank)
      file(RELATIVE_PATH rel ${SOURCE_DIR} ${file})
      string(STRIP "${line}" line)
      set_property(GLOBAL APPEND_STRING PROPERTY layer_violations "  ${rel}: ${line} (${rule})\n")
    endif()
  endforeach()
endfunction()

set(files_checked 0)
foreach(layer IN LISTS layers)
  list(FIND layers ${layer} rank)
  file(GLOB_RECURSE files ${SOURCE_DIR}/include/resoct/${layer}/* ${SOURCE_DIR}/src/core/${layer}/*)
  foreach(f IN LISTS files)
    check_file(${f} ${rank} "${layer}/ includes only the layers before it")
    math(EXPR files_checked "${files_checked} + 1")
  endforeach()
endforeach()
# The backends depend on the core only: everything but io/.
list(FIND layers io io_rank)
math(EXPR core_top "${io_rank} - 1")
file(GLOB_RECURSE files ${SOURCE_DIR}/include/resoct/cpu/* ${SOURCE_DIR}/include/resoct/vulkan/*
     ${SOURCE_DIR}/src/backend_cpu/* ${SOURCE_DIR}/src/backend_vulkan/*)
foreach(f IN LISTS files)
  check_file(${f} ${core_top} "a backend includes the core only, never io/")
  math(EXPR files_checked "${files_checked} + 1")
endforeach()

get_property(bad GLOBAL PROPERTY layer_violations)
if(bad)
  message(FATAL_ERROR "includes against the layer order of docs/architecture.md §1.0 (bottom up: "
                      "${layers}):\n${bad}")
endif()
message(STATUS "${files_checked} files keep the layer order")
