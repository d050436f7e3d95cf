#include "support/expect_error.hpp"

namespace resoct::test {

::testing::AssertionResult throws_error(const std::function<void()>& fn, ErrorCode code,
                                        const std::string& needle) {
  try {
    fn();
  } catch (const Error& e) {
    const std::string msg = e.what();
    if (e.code() != code) {
      return ::testing::AssertionFailure() << "error code " << to_string(e.code()) << " instead of "
                                           << to_string(code) << ": " << msg;
    }
    if (msg.find(needle) == std::string::npos) {
      return ::testing::AssertionFailure() << "message lacks '" << needle << "': " << msg;
    }
    return ::testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "threw a non-resoct exception: " << e.what();
  }
  return ::testing::AssertionFailure() << "did not throw (expected " << to_string(code) << ")";
}

}  // namespace resoct::test
