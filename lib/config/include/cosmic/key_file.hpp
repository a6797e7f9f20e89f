// Reading a key file (issue 36; cosmic/secret_key.hpp): a regular file only its owner may read or
// write, holding the key as hexadecimal digits. The configuration loader reports its refusals
// located at the `key_file` key; libcosmic-client reads the key a component's segment names.
//
// Threads: any; reads the file system.
#pragma once

#include <cstddef>
#include <string>

#include "cosmic/result.hpp"
#include "cosmic/secret_key.hpp"

namespace cosmic {

// The key in `path`, of `min_bytes` to `max_bytes` bytes; else why not, starting with what could
// not be done ("cannot use key file PATH: ..." or "key file PATH holds no key: ..."), never quoting
// the file's content.
Result<SecretKey> read_key_file(const std::string& path, std::size_t min_bytes, std::size_t max_bytes);

// The bytes of `path`, a regular file of at most `max_bytes` that only its owner may read or write
// and that this process's user (or root) owns, as a PEM private key's file must be (a CA's key that
// `cosmicctl security permissions --sign-with` signs with); else why not ("cannot use PATH: ...").
Result<std::string> read_private_file(const std::string& path, std::size_t max_bytes);

}  // namespace cosmic
