// The kernel headers must compile as GLSL too: run glslangValidator on a compute shader that
// includes them and calls every encode/decode function.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace {
bool have_glslang() {
  return std::system("command -v glslangValidator > /dev/null 2>&1") == 0;
}
}  // namespace

TEST(KernelGlsl, HeadersCompileForVulkan12) {
  if (!have_glslang()) GTEST_SKIP() << "glslangValidator not on PATH (Debian: glslang-tools)";
  const std::string src = RESOCT_SOURCE_DIR;
  const std::string out = std::string(RESOCT_BINARY_DIR) + "/kernel_headers_check.spv";
  const std::string cmd = "glslangValidator -V --target-env vulkan1.2 -I\"" + src +
                          "/include\" -o \"" + out + "\" \"" + src +
                          "/tests/kernel/kernel_headers_check.comp\"";
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << cmd;
}

TEST(KernelGlsl, BrokenShaderIsRejected) {
  // Guards the test above: the validator really runs and reports failures through the exit code.
  if (!have_glslang()) GTEST_SKIP() << "glslangValidator not on PATH (Debian: glslang-tools)";
  const std::string dir = RESOCT_BINARY_DIR;
  const std::string bad = dir + "/kernel_headers_broken.comp";
  const std::string cmd = "printf '#version 450\\nvoid main() { uint x = 1.0; }\\n' > \"" + bad +
                          "\" && glslangValidator -V --target-env vulkan1.2 -o \"" + dir +
                          "/broken.spv\" \"" + bad + "\" > /dev/null";
  EXPECT_NE(std::system(cmd.c_str()), 0);
}
