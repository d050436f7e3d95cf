#pragma once
// Common entry point of the command-line tools: runs the tool body and turns every error into a
// one-line message on stderr and a non-zero exit code, never a crash or an abort.

#include <cstdio>
#include <exception>
#include <new>

#include <CLI/CLI.hpp>

#include "resoct/base/error.hpp"

namespace resoct::tools {

/// Exit codes: 0 success, 1 resoct::Error (bad input), 2 usage error, 3 anything else.
template <typename Body>
int run_tool(const char* tool, Body&& body) {
  try {
    return body();
  } catch (const CLI::ParseError&) {
    throw;  // handled by CLI11's own exit path in main
  } catch (const resoct::Error& e) {
    std::fprintf(stderr, "%s: error [%s]: %s\n", tool, std::string(to_string(e.code())).c_str(),
                 e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: error [out_of_memory]: host memory exhausted\n", tool);
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return 3;
  }
}

}  // namespace resoct::tools
