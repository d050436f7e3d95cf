#pragma once
// Parsers for the tools' compact option values ("256x256x64", "1,1,2.5", "0,4095") and the
// formatting of sizes in summaries. Every parse error is an invalid_parameter naming the option.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include <glm/vec3.hpp>

#include "resoct/volume/voxel_type.hpp"

namespace CLI {
class App;
}

namespace resoct::tools {

/// "WxHxD" with each a positive integer.
glm::u64vec3 parse_dims(std::string_view s, std::string_view option);
/// "N" (cubic) or "NxNxN"; range checks are left to BrickLayout::validate().
glm::uvec3 parse_brick(std::string_view s, std::string_view option);
/// "X,Y,Z" or one value for all axes; each a positive finite number.
glm::dvec3 parse_spacing(std::string_view s, std::string_view option);
/// "LO,HI" with finite LO < HI.
ValueRange parse_range(std::string_view s, std::string_view option);
/// "FIRST:LAST" with integers FIRST <= LAST < 2^32 (an inclusive range of timepoints).
std::pair<std::uint32_t, std::uint32_t> parse_index_range(std::string_view s,
                                                          std::string_view option);

/// "512 B", "1.5 KiB", "3.2 MiB", "1.1 GiB".
std::string format_bytes(std::uint64_t bytes);

/// Makes CLI11 usage errors print one line, "<tool>: error [usage]: <what>" (plus the hint to
/// run --help on the same line), like the errors of run_tool().
void one_line_usage_errors(CLI::App& app, std::string tool);

}  // namespace resoct::tools
