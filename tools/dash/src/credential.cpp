// The dashboard's token through LoadCredential=: see credential.hpp.
#include "credential.hpp"

#include <cstdlib>
#include <fstream>
#include <iterator>

namespace hoist::dash {

Credential readCredential(const std::string& name) {
  Credential c;
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") {
    c.error = "'" + name + "' is not a credential name (a plain file name)";
    return c;
  }
  const char* dir = std::getenv("CREDENTIALS_DIRECTORY");
  if (dir == nullptr || *dir == '\0') return c;
  const std::string path = std::string(dir) + "/" + name;
  std::ifstream in(path, std::ios::binary);
  if (!in) return c;
  c.found = true;
  std::string v((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (v.size() > 1024) v.resize(1024);
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  if (v.size() < 16 || v.size() > 256) {
    c.error = path + ": the token must have 16 to 256 characters (it has " + std::to_string(v.size()) + ")";
    return c;
  }
  for (const char ch : v)
    if (ch <= ' ' || ch >= 0x7f || ch == ';' || ch == ',' || ch == '"') {
      c.error = path + ": the token must be printable ASCII without spaces, ';', ',' or '\"'";
      return c;
    }
  c.value = std::move(v);
  return c;
}

}  // namespace hoist::dash
