// Writes the seed corpora of the fuzz targets: small valid inputs, deterministic (fixed values,
// fixed codec settings, single-threaded store writer), so the committed files can be checked
// against this program.
//   resoct_fuzz_seeds OUT_DIR                    writes OUT_DIR/<target>/seed-*
//   resoct_fuzz_seeds --check COMMITTED SCRATCH  writes into SCRATCH and fails when a file
//                                                differs from (or is missing in) COMMITTED

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "make_seeds.hpp"
#include "resoct/io/store/brick_store.hpp"
#include "resoct/io/storage/codec.hpp"
#include "resoct/volume/dense_volume.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/scene/scene.hpp"

namespace resoct::fuzz::seeds {

std::vector<std::byte> text_bytes(const std::string& s) {
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

std::vector<std::byte> file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* b = reinterpret_cast<const std::byte*>(c.data());
  return {b, b + c.size()};
}

}  // namespace resoct::fuzz::seeds

namespace {

using namespace resoct;
using namespace resoct::fuzz::seeds;

// Value of voxel (x, y, z) of channel c as a fraction of the type's range: a smooth ramp with a
// hollow (zero) region, so stores get stored, constant and empty bricks.
double pattern(std::uint32_t c, std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  if (x < 4 && y < 4) return 0.0;
  return double((x * 7 + y * 3 + z * 5 + c * 11) % 29) / 28.0;
}

template <typename T>
DenseVolume volume(const VolumeDesc& d, double scale, bool with_nan) {
  std::vector<T> v;
  for (std::uint32_t c = 0; c < d.channels; ++c)
    for (std::uint64_t z = 0; z < d.extent.z; ++z)
      for (std::uint64_t y = 0; y < d.extent.y; ++y)
        for (std::uint64_t x = 0; x < d.extent.x; ++x)
          v.push_back(T(std::round(pattern(c, x, y, z) * scale * 1000.0) / 1000.0));
  if (with_nan) v[v.size() / 2] = std::numeric_limits<T>::quiet_NaN();
  return DenseVolume::from_values<T>(d, v);
}

struct StoreCase {
  const char* name;
  glm::u64vec3 extent;
  std::uint32_t channels;
  VoxelType type;
  BrickLayout layout;
  Codec codec;
  int level;
  std::uint32_t metadata_block;
  bool brick_errors = false;  // the errors section (header flag bit 2)
};

void store_seeds(const fs::path& scratch, std::vector<Seed>& out) {
  const StoreCase cases[] = {
      {"u8-lz4", {8, 8, 8}, 1, VoxelType::u8, {glm::uvec3(4), 1}, Codec::lz4, 0, 4},
      {"u16-zstd-2ch", {12, 5, 3}, 2, VoxelType::u16, {glm::uvec3(4), 0}, Codec::zstd, 3, 4},
      {"f32-lz4hc-nan", {6, 6, 5}, 1, VoxelType::f32, {glm::uvec3(4), 2}, Codec::lz4, 9, 8},
      {"u8-zstd-levels", {16, 4, 4}, 1, VoxelType::u8, {{4, 4, 4}, 1}, Codec::zstd, 1, 16},
      {"u8-constant", {9, 9, 9}, 1, VoxelType::u8, {{8, 4, 4}, 0}, Codec::lz4, 0, 4},
      {"u16-errors-2ch", {16, 8, 8}, 2, VoxelType::u16, {glm::uvec3(4), 1}, Codec::lz4, 0, 4, true},
  };
  fs::create_directories(scratch);
  for (const StoreCase& sc : cases) {
    VolumeDesc d;
    d.extent = sc.extent;
    d.channels = sc.channels;
    d.type = sc.type;
    DenseVolume v;
    const bool constant = std::string(sc.name) == "u8-constant";
    if (sc.type == VoxelType::u8) {
      v = constant ? DenseVolume::from_values<std::uint8_t>(
                         d, std::vector<std::uint8_t>(std::size_t(d.voxel_count()), 0))
                   : volume<std::uint8_t>(d, 255.0, false);
    } else if (sc.type == VoxelType::u16) {
      v = volume<std::uint16_t>(d, 65535.0, false);
    } else {
      v = volume<float>(d, 1.0, true);
    }
    const InMemorySource src(std::move(v), sc.layout, sc.metadata_block, sc.name);
    StoreWriteOptions opt;
    opt.codec = sc.codec;
    opt.level = sc.level;
    opt.metadata_block = sc.metadata_block;
    opt.threads = 1;
    opt.brick_errors = sc.brick_errors;
    const fs::path file = scratch / (std::string(sc.name) + ".rbs");
    write_brick_store(src, file.string(), opt);
    out.push_back(
        {"brick_store", std::string("seed-") + sc.name + ".rbs", file_bytes(file), false});
  }
}

void scene_seeds(std::vector<Seed>& out) {
  // The smallest accepted scene, as a user would write it.
  out.push_back({"scene_json", "seed-minimal.json",
                 text_bytes("{\"camera\": {\"eye\": [2, 0.5, 0.5], \"target\": [0.5, 0.5, 0.5]},\n"
                            " \"channels\": [{\"channel\": 0, \"tf\": [[0, 1, 1, 1, 0.5]]}]}\n")});
  Scene a;
  a.channels.push_back(ChannelSettings{});
  a.channels[0].tf =
      TransferFunction({{0.0, {0, 0, 0, 0}}, {0.25, {1, 0.5, 0, 0.1}}, {1.0, {1, 1, 1, 0.9}}});
  out.push_back({"scene_json", "seed-default.json", text_bytes(scene_to_json(a))});
  Scene b;
  b.camera.projection = Projection::orthographic;
  b.camera.eye = {0.5, -3.0, 0.25};
  b.camera.up = {0.0, 0.0, 1.0};
  b.camera.ortho_height = 1.5;
  b.viewport = {64, 48};
  for (std::uint32_t c : {3u, 0u, 17u}) {
    ChannelSettings s;
    s.channel = c;
    s.finest_level = c % 2;
    s.coarsest_level = 5;
    s.importance = -int(c);
    s.tf = TransferFunction({{0.1, {0, 1, 0, 0}}, {0.9, {0, 1, 0, 1}}});
    b.channels.push_back(s);
  }
  b.step_scale = 0.5;
  b.lod_error_px = 2.0;
  b.ert_opacity = 0.95;
  b.background = {1.0, 1.0, 1.0, 0.0};
  b.effects = {Effect::shading, Effect::shadows};
  out.push_back({"scene_json", "seed-ortho-3ch.json", text_bytes(scene_to_json(b))});
}

void spec_seeds(std::vector<Seed>& out) {
  const char* specs[] = {"procedural:tubes",
                         "procedural:noisefloor:8x8x8",
                         "procedural:turbulence:9x9x9:4",
                         "procedural:mandelbulb:16x16x16:2",
                         "procedural:cells:64x64x8:16",
                         "procedural:constant:1x1x1",
                         "procedural:ramp:5x5x5:3",
                         "procedural:sphere:40x33x17"};
  int i = 0;
  for (const char* s : specs) {
    out.push_back({"source_spec", "seed-" + std::to_string(i++) + ".txt", text_bytes(s)});
  }
}

void codec_seeds(std::vector<Seed>& out) {
  std::vector<std::vector<std::byte>> inputs(3);
  inputs[0].assign(64, std::byte{0});
  for (int i = 0; i < 300; ++i) inputs[1].push_back(std::byte(i * i % 251));
  std::uint32_t x = 12345;  // fixed LCG: incompressible bytes without std's RNG differences
  for (int i = 0; i < 100; ++i)
    inputs[2].push_back(std::byte((x = x * 1103515245u + 12345u) >> 24));
  for (Codec c : {Codec::lz4, Codec::zstd}) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const std::vector<std::byte>& in = inputs[i];
      std::vector<std::byte> b = {std::byte(c == Codec::zstd ? 1 : 0), std::byte(in.size() & 0xFF),
                                  std::byte((in.size() >> 8) & 0xFF),
                                  std::byte((in.size() >> 16) & 0xFF)};
      const std::vector<std::byte> packed = compress(c, 0, in);
      b.insert(b.end(), packed.begin(), packed.end());
      out.push_back(
          {"codec", "seed-" + std::string(to_string(c)) + "-" + std::to_string(i) + ".bin", b});
    }
  }
}

std::vector<Seed> all_seeds(const fs::path& scratch) {
  std::vector<Seed> s;
  store_seeds(scratch / "stores", s);
  scene_seeds(s);
  spec_seeds(s);
  codec_seeds(s);
  format_seeds(scratch, s);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const bool check = argc == 4 && std::strcmp(argv[1], "--check") == 0;
    if (!check && argc != 2) {
      std::fprintf(stderr, "usage: %s OUT_DIR | --check COMMITTED_DIR SCRATCH_DIR\n", argv[0]);
      return 2;
    }
    const fs::path scratch = check ? fs::path(argv[3]) : fs::path(argv[1]) / ".scratch";
    const std::vector<Seed> seeds = all_seeds(scratch);
    int bad = 0;
    for (const Seed& s : seeds) {
      if (check) {
        const fs::path committed = fs::path(argv[2]) / s.target / s.name;
        if (!fs::exists(committed) || (s.exact && file_bytes(committed) != s.bytes)) {
          std::fprintf(stderr,
                       "seed %s is missing or stale (regenerate: scripts/fuzz.sh --seeds)\n",
                       committed.c_str());
          ++bad;
        }
        continue;
      }
      const fs::path dir = fs::path(argv[1]) / s.target;
      fs::create_directories(dir);
      std::ofstream f(dir / s.name, std::ios::binary | std::ios::trunc);
      f.write(reinterpret_cast<const char*>(s.bytes.data()), std::streamsize(s.bytes.size()));
      if (!f) {
        std::fprintf(stderr, "cannot write %s\n", (dir / s.name).c_str());
        return 1;
      }
    }
    if (!check) fs::remove_all(scratch);
    std::printf("%zu seeds %s\n", seeds.size(),
                check ? (bad ? "checked: STALE" : "up to date") : "written");
    return bad == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "resoct_fuzz_seeds: %s\n", e.what());
    return 1;
  }
}
