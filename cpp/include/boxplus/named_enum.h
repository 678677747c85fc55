// boxplus::NamedEnum — one table of names for an enumeration, and one rule for
// reading them.
//
// Every name↔value vocabulary of boxplus (solver methods, damping, the
// initialisation of a pose graph, the pose-error conventions, robust losses)
// is a NamedEnum: each value has one canonical name (what is printed) and any
// aliases (other spellings accepted). Parse applies one input rule everywhere:
// letters are compared case-insensitively and '-' equals '_', so "GN-LS",
// "gn_ls" and "gn-ls" are one name; an unknown name throws boxplus::Error
// listing the canonical names.
#pragma once

#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <string>
#include <vector>

#include "boxplus/errors.h"

namespace boxplus {

template <class V>
class NamedEnum {
 public:
  struct Entry {
    V value;
    std::string name;                  // canonical
    std::vector<std::string> aliases;  // also accepted
  };

  NamedEnum(std::string what, std::initializer_list<Entry> entries)
      : what_(std::move(what)), entries_(entries) {}

  V Parse(const std::string& text) const {
    const std::string key = Key(text);
    for (const Entry& e : entries_) {
      if (Key(e.name) == key) return e.value;
      for (const std::string& a : e.aliases) {
        if (Key(a) == key) return e.value;
      }
    }
    std::string list;
    for (const Entry& e : entries_) list += (list.empty() ? "" : ", ") + e.name;
    throw Error("unknown " + what_ + " '" + text + "' (expected one of " + list + ")");
  }

  const std::string& Name(V value) const {
    for (const Entry& e : entries_) {
      if (e.value == value) return e.name;
    }
    throw Error(what_ + ": a value without a name");
  }

  std::vector<std::string> Names() const {
    std::vector<std::string> out;
    for (const Entry& e : entries_) out.push_back(e.name);
    return out;
  }

 private:
  // The input rule: lower case, '-' as '_'.
  static std::string Key(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) {
      return c == '-' ? '_' : static_cast<char>(std::tolower(c));
    });
    return s;
  }

  std::string what_;
  std::vector<Entry> entries_;
};

}  // namespace boxplus
