// resoct.Source: any BrickSource, opened from a spec the command-line tools accept
// (open_source) or from a numpy array (an InMemorySource), with the metadata a viewer shows.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "numpy_image.hpp"
#include "resoct/base/error.hpp"
#include "resoct/sources/in_memory_source.hpp"
#include "resoct/io/open_source.hpp"

namespace resoct::python {

namespace {

using Source = std::shared_ptr<BrickSource>;

const VolumeDesc& volume(const BrickSource& s) {
  return s.hierarchy().volume();
}

std::uint32_t checked_channel(const BrickSource& s, std::uint32_t channel) {
  if (channel >= volume(s).channels) {
    throw invalid_parameter("channel", std::to_string(channel) + " but the source has " +
                                           std::to_string(volume(s).channels) + " channels");
  }
  return channel;
}

BrickLayout layout_of(std::uint32_t brick, std::uint32_t halo) {
  BrickLayout layout{glm::uvec3(brick), halo};
  layout.validate();
  return layout;
}

Source open_spec(const std::string& spec, std::uint32_t brick, std::uint32_t halo,
                 const std::string& s3_endpoint, bool no_sign_request) {
  SourceOptions options;
  options.s3.endpoint = s3_endpoint;
  options.s3.anonymous = no_sign_request;
  const BrickLayout layout = layout_of(brick, halo);
  py::gil_scoped_release release;  // opening a remote source waits on the network
  return Source(open_source(spec, layout, options));
}

VoxelType voxel_type_of(const py::dtype& dtype) {
  if (dtype.is(py::dtype::of<std::uint8_t>())) return VoxelType::u8;
  if (dtype.is(py::dtype::of<std::uint16_t>())) return VoxelType::u16;
  if (dtype.is(py::dtype::of<float>())) return VoxelType::f32;
  throw invalid_parameter("array",
                          "dtype must be uint8, uint16 or float32, not " + dtype_name(dtype));
}

// The finite value range of each channel of float voxels (an InMemorySource needs a range to
// normalize them; NaN and infinities are left out, as the tools do).
std::vector<ValueRange> float_ranges(const float* v, std::uint32_t channels, std::size_t per) {
  std::vector<ValueRange> ranges;
  for (std::uint32_t c = 0; c < channels; ++c) {
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (std::size_t i = 0; i < per; ++i) {
      const double x = v[c * per + i];
      if (std::isfinite(x)) {
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
    if (!(lo < hi)) {  // constant or without finite values: any non-empty range will do
      lo = std::isfinite(lo) ? lo : 0.0;
      hi = lo + 1.0;
    }
    ranges.push_back(ValueRange{lo, hi});
  }
  return ranges;
}

Source from_array(const py::array& input, const std::tuple<double, double, double>& spacing,
                  const std::optional<std::pair<double, double>>& value_range, std::uint32_t brick,
                  std::uint32_t halo, const std::string& name) {
  if (input.ndim() != 3 && input.ndim() != 4) {
    throw invalid_parameter("array", "must have 3 axes (z, y, x) or 4 (channel, z, y, x), not " +
                                         std::to_string(input.ndim()));
  }
  VolumeDesc d;
  d.type = voxel_type_of(input.dtype());
  // numpy's C order is resoct's: x fastest, channels one after another.
  const py::array a = py::array::ensure(input, py::array::c_style);
  const auto axis = [&](int from_end) { return std::uint64_t(a.shape(a.ndim() - from_end)); };
  d.extent = {axis(1), axis(2), axis(3)};
  d.channels = a.ndim() == 4 ? std::uint32_t(a.shape(0)) : 1u;
  d.spacing = {std::get<0>(spacing), std::get<1>(spacing), std::get<2>(spacing)};
  const std::size_t per = std::size_t(d.extent.x * d.extent.y * d.extent.z);
  if (value_range) {
    d.ranges.assign(d.channels, ValueRange{value_range->first, value_range->second});
  } else if (d.type == VoxelType::f32) {
    d.ranges = float_ranges(static_cast<const float*>(a.data()), d.channels, per);
  }
  d.validate("array");
  std::vector<std::byte> bytes(std::size_t(a.nbytes()));
  std::memcpy(bytes.data(), a.data(), bytes.size());
  const BrickLayout layout = layout_of(brick, halo);
  py::gil_scoped_release release;  // building the coarser levels takes a while for big arrays
  return std::make_shared<InMemorySource>(DenseVolume::from_bytes(d, std::move(bytes)), layout, 16,
                                          name);
}

}  // namespace

void bind_sources(py::module_& m) {
  py::class_<BrickSource, Source>(m, "Source",
                                  "A volume resoct renders: its bricks are read on demand.")
      .def_property_readonly("name", &BrickSource::name)
      .def_property_readonly(
          "extent",
          [](const BrickSource& s) {
            const glm::u64vec3 e = volume(s).extent;
            return py::make_tuple(e.x, e.y, e.z);
          },
          "Level-0 voxels per axis (x, y, z).")
      .def_property_readonly("spacing",
                             [](const BrickSource& s) {
                               const glm::dvec3 v = volume(s).spacing;
                               return py::make_tuple(v.x, v.y, v.z);
                             })
      .def_property_readonly("channels", [](const BrickSource& s) { return volume(s).channels; })
      .def_property_readonly(
          "dtype",
          [](const BrickSource& s) { return std::string(to_string(volume(s).file_type())); },
          "The file's value type ('u8', 'i16', 'f32', ...).")
      .def_property_readonly("levels",
                             [](const BrickSource& s) { return s.hierarchy().level_count(); })
      .def_property_readonly("timepoints", &BrickSource::timepoints)
      .def_property_readonly("timepoint", &BrickSource::timepoint)
      .def(
          "value_range",
          [](const BrickSource& s, std::uint32_t channel) {
            const ValueRange r = volume(s).data_range(checked_channel(s, channel));
            return py::make_tuple(r.lo, r.hi);
          },
          py::arg("channel") = 0,
          "The range a transfer function's [0, 1] spans, in the file's units.")
      .def(
          "data_range",
          [](const BrickSource& s, std::uint32_t channel) {
            const VolumeDesc& v = volume(s);
            const Box3 all{{0, 0, 0}, glm::i64vec3(v.extent)};
            RegionMeta meta;
            {
              py::gil_scoped_release release;
              meta = s.region_meta(checked_channel(s, channel), all);
            }
            return py::make_tuple(meta.min, meta.max);
          },
          py::arg("channel") = 0,
          "Smallest and largest stored value of a channel, from the source's metadata.")
      .def("__repr__", [](const BrickSource& s) {
        const glm::u64vec3 e = volume(s).extent;
        return "<resoct.Source " + s.name() + " " + std::to_string(e.x) + "x" +
               std::to_string(e.y) + "x" + std::to_string(e.z) + ", " +
               std::to_string(volume(s).channels) + " channels>";
      });

  m.def("open_source", &open_spec, py::arg("spec"), py::kw_only(), py::arg("brick") = 32u,
        py::arg("halo") = 1u, py::arg("s3_endpoint") = "", py::arg("no_sign_request") = false,
        ("Opens a source as the command-line tools do: " + std::string(kSourceSpecForms) +
         ". `brick` and `halo` brick the formats that are not brick stores; `s3_endpoint` and "
         "`no_sign_request` are the tools' --s3-endpoint and --no-sign-request.")
            .c_str());
  m.def("from_array", &from_array, py::arg("array"), py::kw_only(),
        py::arg("spacing") = std::make_tuple(1.0, 1.0, 1.0), py::arg("value_range") = py::none(),
        py::arg("brick") = 32u, py::arg("halo") = 1u, py::arg("name") = "array",
        "A source over a numpy array of uint8, uint16 or float32, shaped (z, y, x) or (channel, "
        "z, y, x); `spacing` is (x, y, z). Without `value_range` a float array's finite data "
        "range is used, an integer array's full type range.");
}

}  // namespace resoct::python
