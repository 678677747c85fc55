#include "boxplus/io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "boxplus/errors.h"

namespace boxplus::io {

namespace {

[[noreturn]] void Fail(const std::string& path, const char* doing, int err) {
  throw Error("cannot write '" + path + "': " + doing + ": " + std::strerror(err));
}

// Writes all bytes to fd; false (errno set) on the first failure.
bool WriteAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

std::string Folder(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string BaseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

void WriteDirect(const std::string& path, const std::string& content, bool append) {
  const int fd = ::open(path.c_str(), O_WRONLY | (append ? O_APPEND : O_TRUNC) | O_CLOEXEC);
  if (fd < 0) Fail(path, "open", errno);
  if (!WriteAll(fd, content.data(), content.size())) {
    const int err = errno;
    ::close(fd);
    Fail(path, "write", err);
  }
  if (::close(fd) != 0) Fail(path, "close", errno);
}

void Replace(const std::string& path, const std::string& content, bool append) {
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw Error("cannot write '" + path + "': it is a folder");
  if (exists && !S_ISREG(st.st_mode)) return WriteDirect(path, content, append);
  std::string tmp = Folder(path) + "/." + BaseName(path) + ".XXXXXX";
  std::vector<char> name(tmp.begin(), tmp.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  if (fd < 0) Fail(path, "create a temporary file beside it", errno);
  tmp.assign(name.data());
  auto abandon = [&](const char* doing, int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    Fail(path, doing, err);
  };
  if (append && exists) {
    std::ifstream old(path, std::ios::binary);
    if (!old) abandon("read its previous content", errno);
    std::ostringstream buf;
    buf << old.rdbuf();
    const std::string prev = buf.str();
    if (!WriteAll(fd, prev.data(), prev.size())) abandon("write", errno);
  }
  if (!WriteAll(fd, content.data(), content.size())) abandon("write", errno);
  if (::fsync(fd) != 0) abandon("flush to disk", errno);
  // The mode of the file replaced, else what the umask gives a new file.
  mode_t mode = st.st_mode & 07777;
  if (!exists) {
    const mode_t mask = ::umask(0);
    ::umask(mask);
    mode = 0666 & ~mask;
  }
  if (::fchmod(fd, mode) != 0) abandon("set its mode", errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    Fail(path, "close", err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    Fail(path, "rename the temporary file over it", err);
  }
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& content) {
  Replace(path, content, false);
}

void AppendFileAtomically(const std::string& path, const std::string& content) {
  Replace(path, content, true);
}

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

void WriteAllOrThrow(std::FILE* stream, const std::string& content, const std::string& what) {
  const size_t n = std::fwrite(content.data(), 1, content.size(), stream);
  if (n != content.size() || std::fflush(stream) != 0 || std::ferror(stream)) {
    throw Error("cannot write " + what + ": " + std::strerror(errno));
  }
}

}  // namespace boxplus::io
