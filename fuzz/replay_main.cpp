// Replays inputs through a fuzz target without libFuzzer, so that every committed seed and every
// fixed crasher runs in the ordinary (g++) test suite. Usage: replay PATH... where each PATH is
// a file or a directory (its regular files, in name order). Exits 0 when every input ran; a
// finding aborts after naming the input on stderr.

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

// The input being replayed, for the crash handlers (fixed buffer: no allocation in a handler).
char g_current[4096] = "";

void name_current_input() {
  static const char prefix[] = "replay: failed on input ";
  const ssize_t a = ::write(2, prefix, sizeof prefix - 1);
  const ssize_t b = ::write(2, g_current, std::char_traits<char>::length(g_current));
  const ssize_t c = ::write(2, "\n", 1);
  (void)a, (void)b, (void)c;
}

extern "C" void on_signal(int sig) {
  name_current_input();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

std::vector<fs::path> inputs_of(const fs::path& p) {
  std::vector<fs::path> out;
  if (fs::is_directory(p)) {
    for (const fs::directory_entry& e : fs::directory_iterator(p)) {
      if (e.is_regular_file()) out.push_back(e.path());
    }
    std::sort(out.begin(), out.end());
  } else {
    out.push_back(p);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE|DIR...\n", argv[0]);
    return 2;
  }
  std::set_terminate([] {
    name_current_input();
    std::abort();
  });
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) std::signal(sig, on_signal);
  std::size_t count = 0;
  for (int i = 1; i < argc; ++i) {
    if (!fs::exists(argv[i])) {
      std::fprintf(stderr, "replay: %s does not exist\n", argv[i]);
      return 2;
    }
    for (const fs::path& f : inputs_of(argv[i])) {
      const std::string name = f.string();
      name.copy(g_current, sizeof g_current - 1);
      g_current[std::min(name.size(), sizeof g_current - 1)] = '\0';
      std::ifstream in(f, std::ios::binary);
      const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
      if (!in.good() && !in.eof()) {
        std::fprintf(stderr, "replay: cannot read %s\n", name.c_str());
        return 2;
      }
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      ++count;
    }
  }
  if (count == 0) {
    std::fprintf(stderr, "replay: no inputs found\n");
    return 2;
  }
  std::printf("replay: %zu inputs ran\n", count);
  return 0;
}
