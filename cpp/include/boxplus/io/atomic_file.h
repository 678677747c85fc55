// Writing files without ever losing the user's data.
//
// WriteFileAtomically writes the content to a temporary file in the target's
// own folder, flushes it to disk (fsync) and renames it over the target only
// when every byte was written: a failed write (a full disk, an I/O error)
// removes the temporary, leaves any previous file of that name as it was, and
// throws boxplus::Error naming the target. A target that exists and is not a
// regular file (a device such as /dev/full or /dev/stdout, a FIFO) is written
// directly, and its write errors are thrown too. AppendFileAtomically appends
// the same way (the previous content is copied into the temporary first).
//
// SameFile tells whether two paths name one file (device and inode: links and
// symlinks too), so that a tool can refuse to write over one of its inputs.
#pragma once

#include <cstdio>
#include <string>

namespace boxplus::io {

void WriteFileAtomically(const std::string& path, const std::string& content);
void AppendFileAtomically(const std::string& path, const std::string& content);

// True when both paths exist and name the same file.
bool SameFile(const std::string& a, const std::string& b);

// Writes all of `content` to an open stream (stdout) and flushes it; throws
// boxplus::Error naming `what` when any byte could not be written.
void WriteAllOrThrow(std::FILE* stream, const std::string& content, const std::string& what);

}  // namespace boxplus::io
