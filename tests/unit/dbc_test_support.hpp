// Shared by the unit tests that read DBC text of their own: one message of a parsed file by name.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "cosmic/dbc.hpp"

namespace cosmic::test {

// `file`'s message `name`; a test failure (and the first message) when the file has errors or no
// such message.
inline const DbcMessage& message_named(const DbcFile& file, const std::string& name) {
  EXPECT_TRUE(file.ok()) << (file.errors.empty() ? "" : file.errors[0].message);
  for (const auto& m : file.messages) {
    if (m.name == name) return m;
  }
  ADD_FAILURE() << "no message " << name;
  return file.messages.front();
}

}  // namespace cosmic::test
