// Which sanitizer this unit is built with (g++ defines __SANITIZE_*__, clang answers
// __has_feature), for the few tests a sanitizer runtime cannot run (docs/testing.md
// "Sanitizers"): RESOCT_TEST_ASAN, RESOCT_TEST_TSAN (1 or 0) and RESOCT_TEST_SANITIZED (either).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define RESOCT_TEST_ASAN 1
#endif
#if defined(__SANITIZE_THREAD__)
#define RESOCT_TEST_TSAN 1
#endif
#if defined(__has_feature)
#if __has_feature(address_sanitizer) && !defined(RESOCT_TEST_ASAN)
#define RESOCT_TEST_ASAN 1
#endif
#if __has_feature(thread_sanitizer) && !defined(RESOCT_TEST_TSAN)
#define RESOCT_TEST_TSAN 1
#endif
#endif
#ifndef RESOCT_TEST_ASAN
#define RESOCT_TEST_ASAN 0
#endif
#ifndef RESOCT_TEST_TSAN
#define RESOCT_TEST_TSAN 0
#endif
#define RESOCT_TEST_SANITIZED (RESOCT_TEST_ASAN || RESOCT_TEST_TSAN)
