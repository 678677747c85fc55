// io/atomic_file.h: a write is whole or not at all, keeps the mode of the file
// it replaces, leaves no temporary behind, and a failure names the file.
#include "boxplus/io/atomic_file.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "boxplus/errors.h"

namespace boxplus::io {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path FreshFolder(const char* name) {
  const fs::path d = fs::temp_directory_path() /
                     (std::string("boxplus_atomic_") + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(AtomicFile, ReplacesWholeKeepsTheModeAndLeavesNoTemporary) {
  const fs::path d = FreshFolder("replace");
  const fs::path f = d / "out.g2o";
  WriteFileAtomically(f.string(), "first\n");
  ::chmod(f.c_str(), 0640);
  WriteFileAtomically(f.string(), "second\n");
  EXPECT_EQ(Read(f), "second\n");
  struct stat st {};
  ASSERT_EQ(::stat(f.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
  AppendFileAtomically(f.string(), "third\n");
  EXPECT_EQ(Read(f), "second\nthird\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++entries;
  EXPECT_EQ(entries, 1);
  fs::remove_all(d);
}

TEST(AtomicFile, AFailedWriteNamesTheFileAndKeepsThePreviousOne) {
  // A write that fails half way, for every user root included: a file-size
  // limit makes write() fail with EFBIG after a few bytes (SIGXFSZ ignored).
  const fs::path d = FreshFolder("full");
  const fs::path f = d / "result.yml";
  WriteFileAtomically(f.string(), "kept\n");
  struct rlimit old_limit {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old_limit), 0);
  struct rlimit small = old_limit;
  small.rlim_cur = 8;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  std::string what;
  try {
    WriteFileAtomically(f.string(), std::string(4096, 'x'));
  } catch (const Error& e) {
    what = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(what.find("result.yml"), std::string::npos) << "error: '" << what << "'";
  EXPECT_EQ(Read(f), "kept\n");
  int entries = 0;  // no temporary file left behind
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++entries;
  EXPECT_EQ(entries, 1);
  fs::remove_all(d);
}

TEST(AtomicFile, AnImpossibleWriteNamesTheFileAndLeavesNothing) {
  const fs::path d = FreshFolder("impossible");
  const fs::path not_a_folder = d / "plain";
  WriteFileAtomically(not_a_folder.string(), "x");
  const fs::path f = not_a_folder / "out.g2o";  // its folder is a file
  try {
    WriteFileAtomically(f.string(), "y");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("plain/out.g2o"), std::string::npos) << e.what();
  }
  EXPECT_THROW(WriteFileAtomically(d.string(), "z"), Error);  // a folder is not replaced
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++entries;
  EXPECT_EQ(entries, 1);
  fs::remove_all(d);
}

TEST(AtomicFile, ADeviceIsWrittenDirectlyAndItsErrorsRaised) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  EXPECT_THROW(WriteFileAtomically("/dev/full", "x"), Error);
  EXPECT_THROW(AppendFileAtomically("/dev/full", "x"), Error);
  EXPECT_TRUE(fs::is_character_file("/dev/full"));  // written to, never replaced
  std::FILE* full = std::fopen("/dev/full", "w");
  ASSERT_NE(full, nullptr);
  EXPECT_THROW(WriteAllOrThrow(full, std::string(1 << 16, 'x'), "stdout"), Error);
  std::fclose(full);
}

TEST(AtomicFile, SameFileSeesLinks) {
  const fs::path d = FreshFolder("same");
  const fs::path f = d / "in.g2o", link = d / "link.g2o", hard = d / "hard.g2o";
  WriteFileAtomically(f.string(), "x");
  fs::create_symlink(f, link);
  fs::create_hard_link(f, hard);
  EXPECT_TRUE(SameFile(f.string(), link.string()));
  EXPECT_TRUE(SameFile(f.string(), hard.string()));
  EXPECT_FALSE(SameFile(f.string(), (d / "other").string()));
  fs::remove_all(d);
}

}  // namespace
}  // namespace boxplus::io
