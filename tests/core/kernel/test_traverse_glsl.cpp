// The traversal kernel (kernel/traverse.glsl.h and everything it includes) must also be valid
// GLSL: compile tests/kernel/traverse_check.comp, which defines every accessor over storage
// buffers and calls resoct_render_pixel, with glslangValidator for Vulkan 1.2.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace {

bool have_glslang() {
  return std::system("command -v glslangValidator > /dev/null 2>&1") == 0;
}

TEST(TraverseGlsl, KernelCompilesAsGlsl) {
  if (!have_glslang()) GTEST_SKIP() << "glslangValidator not on PATH";
  const std::string src = RESOCT_SOURCE_DIR;
  const std::filesystem::path out = std::filesystem::path(RESOCT_BINARY_DIR) / "traverse_check.spv";
  std::filesystem::remove(out);
  const std::string cmd = "glslangValidator -V --target-env vulkan1.2 -I\"" + src +
                          "/include\" -o \"" + out.string() + "\" \"" + src +
                          "/tests/kernel/traverse_check.comp\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_TRUE(std::filesystem::exists(out));
}

}  // namespace
