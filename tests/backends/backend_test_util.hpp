#pragma once
// Backend-parameterized suites: a fixture whose parameter names the backend ("cpu", or "vulkan"
// when the build has it). The Vulkan instance runs with the validation layer (synchronization
// validation included) and fails the test on any message; on a machine without a Vulkan device
// it skips with the reason.
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cpu/cpu_test_util.hpp"
#include "resoct/cpu/cpu_backend.hpp"
#ifdef RESOCT_TEST_VULKAN
#include "resoct/vulkan/devices.hpp"
#include "resoct/vulkan/vulkan_backend.hpp"
#include "support/vulkan_required.hpp"
#endif

namespace resoct::test {

/// The backends the parameterized suites run on.
inline std::vector<std::string> test_backends() {
#ifdef RESOCT_TEST_VULKAN
  return {"cpu", "vulkan"};
#else
  return {"cpu"};
#endif
}

class BackendTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (GetParam() == "cpu") {
      backend_ = std::make_unique<cpu::CpuBackend>(1);
      return;
    }
#ifdef RESOCT_TEST_VULKAN
    if (vk::list_devices().empty()) RESOCT_SKIP_WITHOUT_VULKAN("no Vulkan device on this machine");
    BackendOptions o;
    o.validation = true;
    auto v = std::make_unique<vk::VulkanBackend>(o);
    vulkan_ = v.get();
    backend_ = std::move(v);
#else
    FAIL() << "backend " << GetParam() << " is not built";
#endif
  }

  void TearDown() override {
#ifdef RESOCT_TEST_VULKAN
    if (vulkan_ != nullptr) {
      EXPECT_EQ(vulkan_->validation_messages(), 0u);
      for (const std::string& m : vulkan_->validation_log()) ADD_FAILURE() << "validation: " << m;
    }
#endif
  }

  /// Renders one frame of the resident state on the test's backend.
  Rendered render(const ResidentScene& rs, const Scene& scene, const FrameOptions& options = {}) {
    rs.upload(*backend_);
    FrameResult r;
    backend_->render(rs.tables(scene, options), r);
    return {r.image, r.stats, r.brick_requests, r.node_requests};
  }

  Backend& backend() {
    return *backend_;
  }

  /// The device's loop guard (VulkanBackend::loop_iteration_limit), 0 when it has none.
  std::uint32_t loop_limit() const {
#ifdef RESOCT_TEST_VULKAN
    if (vulkan_ != nullptr) return vulkan_->loop_iteration_limit();
#endif
    return 0;
  }

 private:
  std::unique_ptr<Backend> backend_;
#ifdef RESOCT_TEST_VULKAN
  vk::VulkanBackend* vulkan_ = nullptr;
#endif
};

/// "HardCases/BackendHardCases.Name/cpu" rather than ".../0".
inline std::string backend_param_name(const ::testing::TestParamInfo<std::string>& info) {
  return info.param;
}

}  // namespace resoct::test
