// check_page_table_config: the page-table sizes a backend accepts are exactly those the 32-bit
// device request keys can name (kernel/request_key.glsl.h).
#include <gtest/gtest.h>

#include "resoct/backend/backend.hpp"
#include "resoct/kernel/request_key.glsl.h"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

BackendConfig config_with(std::uint32_t pool_blocks, std::uint32_t directory_entries) {
  BackendConfig c;
  c.page_pool_blocks = pool_blocks;
  c.directory_entries = directory_entries;
  return c;
}

TEST(BackendConfigCheck, AcceptsEveryPoolAndDirectorySizeTheKeysCanName) {
  EXPECT_NO_THROW(check_page_table_config(config_with(1, 0)));
  EXPECT_NO_THROW(check_page_table_config(config_with(kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS,
                                                      kernel::RESOCT_REQUEST_MAX_DIRECTORY - 1)));
}

TEST(BackendConfigCheck, RejectsPoolsAndDirectoriesBeyondTheKeys) {
  EXPECT_RESOCT_ERROR(check_page_table_config(config_with(0, 1)), ErrorCode::invalid_argument,
                      "page_pool_blocks");
  EXPECT_RESOCT_ERROR(
      check_page_table_config(config_with(kernel::RESOCT_REQUEST_MAX_POOL_BLOCKS + 1, 1)),
      ErrorCode::invalid_argument, "page_pool_blocks");
  EXPECT_RESOCT_ERROR(check_page_table_config(config_with(1, kernel::RESOCT_REQUEST_MAX_DIRECTORY)),
                      ErrorCode::invalid_argument, "directory_entries");
}

}  // namespace
}  // namespace resoct
