# The README's embedding snippets are the example files, verbatim, each in its own fenced block:
# examples/02_render_frame.cpp in ```cpp and examples/python/render_frame.py in ```python.
# Input: -DSOURCE_DIR.
file(READ ${SOURCE_DIR}/README.md readme)
foreach(pair "cpp:examples/02_render_frame.cpp" "python:examples/python/render_frame.py")
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 lang)
  list(GET pair 1 file)
  file(READ ${SOURCE_DIR}/${file} text)
  string(FIND "${readme}" "```${lang}\n${text}```\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "README.md does not quote ${file} verbatim in a ```${lang} block; copy the "
                        "file's current text into it")
  endif()
endforeach()
message(STATUS "README quotes the example files verbatim")
