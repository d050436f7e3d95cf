#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "resoct/io/storage/byte_store.hpp"
#include "resoct/base/error.hpp"
#include "support/expect_error.hpp"

namespace resoct {
namespace {

class DirectoryStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = std::filesystem::path(RESOCT_BINARY_DIR) / "test_byte_store" /
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(root_);
    std::filesystem::create_directories(root_ / "0");
    std::ofstream(root_ / "0" / "1.2.3", std::ios::binary) << "0123456789";
  }
  std::filesystem::path root_;
};

TEST_F(DirectoryStoreTest, ReadsWholeObjectsAndRanges) {
  auto store = open_directory_store(root_.string());
  auto whole = store->get("0/1.2.3", 1024);
  ASSERT_TRUE(whole.has_value());
  ASSERT_EQ(whole->size(), 10u);
  EXPECT_EQ(char((*whole)[0]), '0');
  EXPECT_EQ(char((*whole)[9]), '9');
  auto part = store->get_range("0/1.2.3", 3, 4);
  ASSERT_EQ(part.size(), 4u);
  EXPECT_EQ(char(part[0]), '3');
  EXPECT_EQ(char(part[3]), '6');
  EXPECT_EQ(store->location("0/1.2.3"), (root_ / "0" / "1.2.3").string());
}

TEST_F(DirectoryStoreTest, MissingObjectIsAnAnswerNotAnError) {
  auto store = open_directory_store(root_.string());
  EXPECT_FALSE(store->get("0/9.9.9", 1024).has_value());
}

TEST_F(DirectoryStoreTest, OversizeObjectAndShortRangeAreErrorsNamingTheFile) {
  auto store = open_directory_store(root_.string());
  EXPECT_RESOCT_ERROR(store->get("0/1.2.3", 9), ErrorCode::out_of_range, "1.2.3");
  EXPECT_RESOCT_ERROR(store->get_range("0/1.2.3", 8, 3), ErrorCode::truncated, "offset 8");
  EXPECT_RESOCT_ERROR(store->get_range("0/1.2.3", 11, 0), ErrorCode::truncated, "1.2.3");
  EXPECT_RESOCT_ERROR(store->get_range("0/1.2.3", 0, ~std::uint64_t(0)), ErrorCode::truncated,
                      "1.2.3");
}

TEST_F(DirectoryStoreTest, HostileKeysCannotLeaveTheStore) {
  auto store = open_directory_store(root_.string());
  for (const char* key : {"", "/etc/passwd", "../x", "0/../../x", "0//1", "./0", "0/."}) {
    EXPECT_RESOCT_ERROR(store->get(key, 1024), ErrorCode::invalid_argument, "key") << key;
  }
}

TEST(DirectoryStore, RootMustBeADirectory) {
  EXPECT_RESOCT_ERROR(open_directory_store("/nonexistent/resoct/store"), ErrorCode::io,
                      "/nonexistent/resoct/store");
}

}  // namespace
}  // namespace resoct
