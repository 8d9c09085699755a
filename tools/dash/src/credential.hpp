// hoist/dash credential.hpp -- the dashboard's token, read through systemd's
// LoadCredential= (the file $CREDENTIALS_DIRECTORY/<name>), never from the
// command line or the environment (both visible to every local user).
// Called once by main.cpp at start-up.
#pragma once

#include <string>

namespace hoist::dash {

/// The outcome of reading a credential.
struct Credential {
  bool found = false;  ///< $CREDENTIALS_DIRECTORY/<name> exists
  std::string value;   ///< the token (one line, trailing newline removed) when found and valid
  std::string error;   ///< why it is unusable ("" when fine or not found)
};

/// Reads $CREDENTIALS_DIRECTORY/<name>: a token of 16..256 printable ASCII
/// characters without spaces (a trailing newline is dropped).  `name` must
/// be a plain file name.
Credential readCredential(const std::string& name);

}  // namespace hoist::dash
