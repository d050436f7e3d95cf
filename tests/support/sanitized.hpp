// RESOCT_TEST_SANITIZED: 1 when this unit is built with AddressSanitizer or ThreadSanitizer
// (g++ defines __SANITIZE_*__, clang answers __has_feature), for the few tests a sanitizer
// runtime cannot run (docs/testing.md "Sanitizers").
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define RESOCT_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define RESOCT_TEST_SANITIZED 1
#endif
#endif
#ifndef RESOCT_TEST_SANITIZED
#define RESOCT_TEST_SANITIZED 0
#endif
