// resoct-render as a process: renders the shipped scenes from procedural volumes and from a brick
// store in every mode, writes a readable PNG and a stats.json with the documented fields, and
// fails with one line naming the bad parameter or file, leaving no output behind.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/test_brick_store_util.hpp"
#include "support/tool_process.hpp"
#include "resoct/image.hpp"

using resoct::test::slurp;
using resoct::test::TempDir;
using resoct::test::ToolRun;

namespace {

ToolRun run(const TempDir& dir, const std::string& tool, const std::string& args) {
  return resoct::test::run_tool_process(dir.path().string(), tool, args);
}

std::string scene(const std::string& name) {
  return std::string(RESOCT_SOURCE_DIR) + "/examples/scenes/" + name + ".json";
}

std::string render_args(const std::string& volume, const std::string& scene_path,
                        const std::string& png, const std::string& stats) {
  return "--volume " + volume + " --scene '" + scene_path + "' --width 40 --height 32 --converge" +
         " --threads 1 --out '" + png + "' --stats '" + stats + "'";
}

TEST(RenderTool, ConvergesAndWritesPngAndStatsInEveryMode) {
  TempDir dir;
  for (const char* mode : {"residency", "pagetable", "octree"}) {
    const std::string png = dir.file(std::string(mode) + ".png");
    const std::string stats = dir.file(std::string(mode) + ".json");
    const ToolRun r = run(
        dir, RESOCT_RENDER,
        render_args("procedural:tubes:64x64x64", scene("tubes"), png, stats) + " --mode " + mode);
    ASSERT_EQ(r.exit_code, 0) << mode << ": " << r.err;
    const resoct::Image img = resoct::read_png(png);
    EXPECT_EQ(img.width(), 40u);
    EXPECT_EQ(img.height(), 32u);
    const nlohmann::json j = nlohmann::json::parse(slurp(stats));
    for (const char* key : {"frames", "converged", "ms_per_frame_steady", "samples_per_ray",
                            "nodes_per_ray", "bricks_touched", "working_set_bytes",
                            "requests_total", "requests_dropped", "cap_hits"}) {
      EXPECT_TRUE(j.contains(key)) << mode << " lacks " << key;
    }
    EXPECT_EQ(j["mode"], mode);
    EXPECT_TRUE(j["converged"].get<bool>()) << mode;
    EXPECT_EQ(j["cap_hits"].get<std::uint64_t>(), 0u) << mode;
    EXPECT_GT(j["samples_per_ray"].get<double>(), 0.0) << mode;
    EXPECT_GT(j["bricks_touched"].get<std::uint64_t>(), 0u) << mode;
  }
}

TEST(RenderTool, RendersAStoreWrittenByConvert) {
  TempDir dir;
  const std::string store = dir.file("sphere.rbs");
  const ToolRun c = run(dir, RESOCT_CONVERT, "procedural:sphere:48x48x48 '" + store + "'");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string png = dir.file("sphere.png"), stats = dir.file("sphere.json");
  const ToolRun r = run(dir, RESOCT_RENDER, render_args(store, scene("sphere"), png, stats));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(slurp(stats))["converged"].get<bool>());
  EXPECT_EQ(resoct::read_png(png).width(), 40u);
}

// The shipped effect scenes: stats.json counts gradients and shadow rays exactly when the scene
// declares effects that need them.
TEST(RenderTool, EffectScenesReportGradientsAndShadowRays) {
  TempDir dir;
  struct Case {
    const char* volume;
    const char* scene;
    bool gradients;
    bool shadows;
  };
  for (const Case& c : {Case{"procedural:sphere:48x48x48", "sphere_iso", true, true},
                        Case{"procedural:tubes:48x48x48", "tubes_shaded", true, true},
                        Case{"procedural:tubes:48x48x48", "tubes_mip", false, false},
                        Case{"procedural:tubes:48x48x48", "tubes", false, false}}) {
    const std::string png = dir.file(std::string(c.scene) + ".png");
    const std::string stats = dir.file(std::string(c.scene) + ".json");
    const ToolRun r = run(dir, RESOCT_RENDER, render_args(c.volume, scene(c.scene), png, stats));
    ASSERT_EQ(r.exit_code, 0) << c.scene << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(stats));
    EXPECT_TRUE(j["converged"].get<bool>()) << c.scene;
    EXPECT_EQ(j["gradient_evals"].get<std::uint64_t>() > 0, c.gradients) << c.scene;
    EXPECT_EQ(j["shadow_rays"].get<std::uint64_t>() > 0, c.shadows) << c.scene;
    EXPECT_EQ(j["cap_hits"].get<std::uint64_t>(), 0u) << c.scene;
  }
}

TEST(RenderTool, BadInputFailsWithOneLineAndLeavesNothing) {
  TempDir dir;
  const std::string png = dir.file("x.png"), stats = dir.file("x.json");
  struct Case {
    std::string args;
    std::string needle;
  };
  const std::string ok_volume = "procedural:tubes:32x32x32";
  const Case cases[] = {
      {render_args(ok_volume, dir.file("missing.json"), png, stats), "missing.json"},
      {render_args("procedural:nosuch", scene("tubes"), png, stats), "nosuch"},
      {render_args(dir.file("absent.rbs"), scene("tubes"), png, stats), "absent.rbs"},
      {render_args(ok_volume, scene("tubes"), png, stats) + " --mode fastest", "mode"},
      {render_args(ok_volume, scene("tubes"), png, stats) + " --backend nosuch", "backend"},
      {render_args(ok_volume, scene("tubes"), dir.file("no/dir/x.png"), stats), "no/dir"},
      // The cells scene shows channels 0-3; a one-channel volume has only channel 0.
      {render_args(ok_volume, scene("cells"), png, stats), "channel"},
  };
  for (const Case& c : cases) {
    const ToolRun r = run(dir, RESOCT_RENDER, c.args);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_FALSE(std::filesystem::exists(png)) << c.args;
    EXPECT_FALSE(std::filesystem::exists(stats)) << c.args;
    const std::string last_line = r.err.substr(r.err.rfind('\n', r.err.size() - 2) + 1);
    EXPECT_NE(last_line.find("error"), std::string::npos) << r.err;
  }
}

}  // namespace
