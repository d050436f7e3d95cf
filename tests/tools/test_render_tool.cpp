// resoct-render as a process: renders the shipped scenes from procedural volumes and from a brick
// store in every mode, writes a readable PNG and a stats.json with the documented fields, and
// fails with one line naming the bad parameter or file, leaving no output behind. With the Vulkan
// backend built: lists the devices (lavapipe where its ICD is installed), renders every mode with
// --backend vulkan under validation like the CPU backend, and rejects a bad --device in one line.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/io/store/test_brick_store_util.hpp"
#include "support/tool_process.hpp"
#include "support/vulkan_required.hpp"
#include "resoct/backend/image.hpp"

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

// Without --scene the tool renders the volume's overview (overview_scene): converged, a picture
// with the channels' colours, and "overview" as the scene in stats.json.
TEST(RenderTool, RendersTheOverviewWithoutAScene) {
  TempDir dir;
  const std::string png = dir.file("overview.png"), stats = dir.file("overview.json");
  const ToolRun r = run(dir, RESOCT_RENDER,
                        "--volume procedural:tubes:64x64x64 --width 40 --height 32 --converge "
                        "--threads 1 --out '" +
                            png + "' --stats '" + stats + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const resoct::Image img = resoct::read_png(png);
  ASSERT_EQ(img.width(), 40u);
  ASSERT_EQ(img.height(), 32u);
  std::size_t lit = 0;
  for (const glm::vec4& p : img.pixels()) lit += p.r + p.g + p.b > 0.1f ? 1u : 0u;
  EXPECT_GT(lit, 20u) << "the tubes must show";
  const nlohmann::json j = nlohmann::json::parse(slurp(stats));
  EXPECT_EQ(j["scene"], "overview");
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_GT(j["samples_per_ray"].get<double>(), 0.0);
}

// examples/scenes/slices.json: a window/level slice at z = 0.3 faces the camera; the voxels
// there are mostly 0, which the window shows as grey 0.3 (opaque), unlike the bluish background.
TEST(RenderTool, RendersSlicesAndLens) {
  TempDir dir;
  const std::string png = dir.file("slices.png"), stats = dir.file("slices.json");
  const ToolRun r = run(dir, RESOCT_RENDER,
                        render_args("procedural:tubes:64x64x64", scene("slices"), png, stats));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(stats));
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_EQ(j["cap_hits"].get<std::uint64_t>(), 0u);
  const resoct::Image img = resoct::read_png(png);
  std::uint32_t grey = 0;
  for (const glm::vec4& p : img.pixels()) {
    if (std::abs(p.r - 0.3f) < 0.01f && p.r == p.g && p.g == p.b) ++grey;
  }
  EXPECT_GT(grey, 40u);
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

// --report-accuracy renders the dense reference of the same view: the stats carry the error, it
// is small at a fine step at level 0 and grows when the renderer's step grows (so it measures the
// renderer, not a constant), and the PNG is the renderer's image, not the reference.
TEST(RenderTool, ReportAccuracyComparesWithTheDenseReference) {
  TempDir dir;
  std::map<double, double> rmse;
  for (const double step_scale : {0.5, 4.0}) {
    nlohmann::json sc = nlohmann::json::parse(slurp(scene("tubes")));
    sc["step_scale"] = step_scale;
    // Level 0 only: the reference's level, so that the error is the step's (a 48^3 volume in
    // 40 x 32 pixels would otherwise be drawn from coarser levels at any step).
    for (nlohmann::json& c : sc["channels"]) c["levels"] = {0, 0};
    const std::string scene_path = dir.file("tubes_" + std::to_string(step_scale) + ".json");
    std::ofstream(scene_path) << sc.dump();
    const std::string png = dir.file("a.png"), stats = dir.file("a.json");
    const ToolRun r = run(
        dir, RESOCT_RENDER,
        render_args("procedural:tubes:48x48x48", scene_path, png, stats) + " --report-accuracy");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("accuracy against the dense reference: RMSE"), std::string::npos) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(stats));
    ASSERT_TRUE(j.contains("accuracy"));
    const nlohmann::json& acc = j["accuracy"];
    for (const char* key : {"rmse_rgb", "psnr_rgb_db", "max_abs_rgb", "reference_step",
                            "ms_per_frame_steady", "s_reference_render"}) {
      EXPECT_TRUE(acc.contains(key)) << key;
    }
    EXPECT_EQ(acc["reference_step"].get<double>(), 0.125);
    EXPECT_GE(acc["max_abs_rgb"].get<double>(), acc["rmse_rgb"].get<double>());
    rmse[step_scale] = acc["rmse_rgb"].get<double>();
    EXPECT_EQ(resoct::read_png(png).width(), 40u);
  }
  EXPECT_GT(rmse[0.5], 0.0);
  EXPECT_LT(rmse[0.5], 2.0 / 255.0);
  EXPECT_GT(rmse[4.0], 2.0 * rmse[0.5]);
}

// --lod-error-color: error-bounded LOD from the command line. The loader measures the coarse
// bricks' errors, so a coarse colour error converges with fewer bricks than the footprint, and
// its error against the dense reference is larger than the footprint's (the reference is level 0).
TEST(RenderTool, LodErrorColorTradesBricksForError) {
  TempDir dir;
  std::map<std::string, nlohmann::json> stats_of;
  for (const std::string extra : {"", " --lod-error-color 0.5"}) {
    const std::string png = dir.file("a.png"), stats = dir.file("a.json");
    const ToolRun r = run(dir, RESOCT_RENDER,
                          render_args("procedural:sphere:48x48x48", scene("sphere"), png, stats) +
                              " --report-accuracy" + extra);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    stats_of[extra] = nlohmann::json::parse(slurp(stats));
    EXPECT_TRUE(stats_of[extra]["converged"].get<bool>()) << extra;
  }
  const nlohmann::json& footprint = stats_of[""];
  const nlohmann::json& eb = stats_of[" --lod-error-color 0.5"];
  EXPECT_LT(eb["bricks_uploaded"].get<std::uint64_t>(),
            footprint["bricks_uploaded"].get<std::uint64_t>());
  EXPECT_GT(eb["accuracy"]["rmse_rgb"].get<double>(),
            footprint["accuracy"]["rmse_rgb"].get<double>());
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
      {render_args(ok_volume, scene("tubes"), png, stats) + " --lod-error-color 2",
       "lod-error-color"},
      {render_args(ok_volume, scene("tubes"), dir.file("no/dir/x.png"), stats), "no/dir"},
      // The cells scene shows channels 0-3; a one-channel volume has only channel 0.
      {render_args(ok_volume, scene("cells"), png, stats), "channel"},
      // --report-accuracy: a scene the reference does not model, a level 0 beyond the memory
      // limit (32^3 u8 = 128 KiB as floats, limit 1 MiB: 128^3 needs 8 MiB), a bad step.
      {render_args(ok_volume, scene("sphere_iso"), png, stats) + " --report-accuracy",
       "report-accuracy"},
      {render_args("procedural:tubes:128x128x128", scene("tubes"), png, stats) +
           " --report-accuracy --reference-mb 1",
       "reference-mb"},
      {render_args(ok_volume, scene("tubes"), png, stats) + " --report-accuracy --reference-step 0",
       "reference-step"},
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

// Why the Vulkan tool tests cannot run here, or "" when they can.
std::string vulkan_skip_reason(const TempDir& dir) {
  const ToolRun r = run(dir, RESOCT_RENDER, "--list-devices");
  if (r.err.find("no Vulkan backend") != std::string::npos) return "built without Vulkan";
  if (r.out.find("no Vulkan device") != std::string::npos) return "no Vulkan device";
  return "";
}

std::size_t line_count(const std::string& s) {
  return std::size_t(std::count(s.begin(), s.end(), '\n'));
}

TEST(RenderTool, ListDevicesPrintsEveryDeviceAndLavapipe) {
  TempDir dir;
  if (const std::string why = vulkan_skip_reason(dir); why == "built without Vulkan") {
    GTEST_SKIP() << why;  // nothing to require of a build configured without Vulkan
  } else if (!why.empty()) {
    RESOCT_SKIP_WITHOUT_VULKAN(why);
  }
  const ToolRun r = run(dir, RESOCT_RENDER, "--list-devices");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // "0: <name> (<type>, Vulkan x.y.z, N MiB device-local)" per device, numbered from 0.
  std::istringstream lines(r.out);
  std::string line;
  std::size_t n = 0;
  while (std::getline(lines, line)) {
    EXPECT_EQ(line.rfind(std::to_string(n) + ": ", 0), 0u) << line;
    EXPECT_NE(line.find(", Vulkan 1."), std::string::npos) << line;
    ++n;
  }
  EXPECT_GE(n, 1u);
  // Mesa's lavapipe calls itself "llvmpipe"; CI installs it (issue 5: "CI without a GPU").
  bool lavapipe_installed = false;
  for (const char* dir_path : {"/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"}) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir_path, ec)) {
      lavapipe_installed |= e.path().filename().string().rfind("lvp_icd", 0) == 0;
    }
  }
  if (lavapipe_installed) {
    EXPECT_NE(r.out.find("llvmpipe"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(cpu, Vulkan"), std::string::npos) << r.out;
  }
}

// Every mode on the Vulkan backend: converges, no validation message, and the image equals the
// CPU backend's within 2/255 per channel plus one 8-bit quantization step.
TEST(RenderTool, VulkanBackendRendersEveryModeLikeTheCpuBackend) {
  TempDir dir;
  if (const std::string why = vulkan_skip_reason(dir); why == "built without Vulkan") {
    GTEST_SKIP() << why;  // nothing to require of a build configured without Vulkan
  } else if (!why.empty()) {
    RESOCT_SKIP_WITHOUT_VULKAN(why);
  }
  for (const char* mode : {"residency", "pagetable", "octree"}) {
    std::map<std::string, resoct::Image> images;
    for (const char* backend : {"cpu", "vulkan"}) {
      const std::string stem = std::string(mode) + "-" + backend;
      const std::string png = dir.file(stem + ".png"), stats = dir.file(stem + ".json");
      // Small: lavapipe renders on the CPU, under validation.
      const ToolRun r = run(dir, RESOCT_RENDER,
                            "--volume procedural:tubes:32x32x32 --scene '" + scene("tubes") +
                                "' --width 24 --height 16 --converge --steady-frames 1 --threads 1"
                                " --out '" +
                                png + "' --stats '" + stats + "' --mode " + mode + " --backend " +
                                backend + " --validation");
      ASSERT_EQ(r.exit_code, 0) << stem << ": " << r.err;
      const nlohmann::json j = nlohmann::json::parse(slurp(stats));
      EXPECT_EQ(j["backend"], backend);
      EXPECT_EQ(j["mode"], mode);
      EXPECT_TRUE(j["converged"].get<bool>()) << stem;
      EXPECT_EQ(j["cap_hits"].get<std::uint64_t>(), 0u) << stem;
      EXPECT_GT(j["samples_per_ray"].get<double>(), 0.0) << stem;
      if (std::string(backend) == "vulkan") {
        ASSERT_TRUE(j.contains("validation_messages")) << stem;
        EXPECT_EQ(j["validation_messages"].get<std::uint64_t>(), 0u) << stem << ": " << r.err;
        EXPECT_EQ(r.err.find("validation: "), std::string::npos) << r.err;
      }
      images.emplace(backend, resoct::read_png(png));
    }
    const resoct::Image& a = images.at("cpu");
    const resoct::Image& b = images.at("vulkan");
    ASSERT_EQ(a.width(), b.width());
    ASSERT_EQ(a.height(), b.height());
    float worst = 0.0f;
    for (std::size_t i = 0; i < a.pixels().size(); ++i) {
      for (int c = 0; c < 4; ++c) {
        worst = std::max(worst, std::abs(a.pixels()[i][c] - b.pixels()[i][c]));
      }
    }
    EXPECT_LE(worst, 3.0f / 255.0f + 1e-6f) << mode;
  }
}

TEST(RenderTool, BadVulkanDeviceFailsWithOneLine) {
  TempDir dir;
  if (const std::string why = vulkan_skip_reason(dir); why == "built without Vulkan") {
    GTEST_SKIP() << why;
  }
  const std::string png = dir.file("x.png"), stats = dir.file("x.json");
  for (const char* device : {"no-such-gpu-xyz", "999"}) {
    const ToolRun r = run(dir, RESOCT_RENDER,
                          render_args("procedural:tubes:32x32x32", scene("tubes"), png, stats) +
                              " --backend vulkan --device " + device);
    EXPECT_NE(r.exit_code, 0) << device;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("device"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(png));
    EXPECT_FALSE(std::filesystem::exists(stats));
  }
}

}  // namespace
