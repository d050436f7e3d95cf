// The value types of users' files and how the three voxel types keep them (data_mapping), and
// VolumeDesc's view of a mapped volume in the file's units.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "resoct/base/error.hpp"
#include "resoct/volume/volume_desc.hpp"
#include "resoct/volume/voxel_type.hpp"
#include "support/expect_error.hpp"

using namespace resoct;

namespace {

TEST(DataType, MappingKeepsSignedIntegersExactlyAndRoundsOnlyWideTypes) {
  EXPECT_EQ(data_mapping(DataType::u8), (DataMapping{VoxelType::u8, 0.0, true}));
  EXPECT_EQ(data_mapping(DataType::u16), (DataMapping{VoxelType::u16, 0.0, true}));
  EXPECT_EQ(data_mapping(DataType::f32), (DataMapping{VoxelType::f32, 0.0, true}));
  EXPECT_EQ(data_mapping(DataType::i8), (DataMapping{VoxelType::u8, 128.0, true}));
  EXPECT_EQ(data_mapping(DataType::i16), (DataMapping{VoxelType::u16, 32768.0, true}));
  EXPECT_EQ(data_mapping(DataType::i32), (DataMapping{VoxelType::f32, 0.0, false}));
  EXPECT_EQ(data_mapping(DataType::u32), (DataMapping{VoxelType::f32, 0.0, false}));
  EXPECT_EQ(data_mapping(DataType::f64), (DataMapping{VoxelType::f32, 0.0, false}));
  // The offsets take the signed ranges exactly onto the unsigned ones.
  for (DataType t : {DataType::i8, DataType::i16}) {
    const DataMapping m = data_mapping(t);
    const double lo = t == DataType::i8 ? -128.0 : -32768.0;
    EXPECT_EQ(lo + m.offset, default_range(m.stored).lo);
    EXPECT_EQ(-lo - 1.0 + m.offset, default_range(m.stored).hi);
  }
  for (int code = 0; code <= 7; ++code) {
    const auto t = DataType(code);
    EXPECT_EQ(parse_data_type(to_string(t)), t);
    EXPECT_EQ(data_size(t) >= voxel_size(data_mapping(t).stored), true);
  }
  EXPECT_EQ(parse_data_type("int16"), DataType::i16);
  EXPECT_EQ(parse_data_type("double"), DataType::f64);
  EXPECT_EQ(parse_data_type("i64"), std::nullopt);
  EXPECT_EQ(describe_mapping(DataType::u16), "u16");
  EXPECT_EQ(describe_mapping(DataType::i16), "i16 (kept as u16, value + 32768: exact)");
  EXPECT_EQ(describe_mapping(DataType::u32), "u32 (kept as f32: rounded)");
}

TEST(DataType, VolumeDescReportsRangesInTheFilesUnits) {
  VolumeDesc d;
  d.type = VoxelType::u16;
  d.data_type = DataType::i16;
  d.ranges = {ValueRange{31744.0, 35839.0}};
  EXPECT_EQ(d.file_type(), DataType::i16);
  EXPECT_EQ(d.value_offset(), 32768.0);
  EXPECT_EQ(d.data_range(0), (ValueRange{-1024.0, 3071.0}));
  EXPECT_NO_THROW(d.validate());
  VolumeDesc plain;
  plain.type = VoxelType::f32;
  EXPECT_EQ(plain.file_type(), DataType::f32);
  EXPECT_EQ(plain.value_offset(), 0.0);
  EXPECT_EQ(plain.data_range(0), plain.range(0));
  // A data type the voxel type does not keep is a contradiction, named as such.
  d.type = VoxelType::u8;
  EXPECT_RESOCT_ERROR(d.validate("ct"), ErrorCode::invalid_argument, "ct: parameter 'data_type'");
}

}  // namespace
