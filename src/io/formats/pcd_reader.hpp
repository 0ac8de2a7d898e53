// PCD reading from any source of bytes (pcd_reader.cpp): a file's (read_pcd) or standard
// input's (cloud_content.cpp). Private to the library.
#pragma once
#include <proxseg/core/frame.hpp>

#include <cstddef>
#include <functional>
#include <string>

namespace proxseg::detail {

// The PCD whose bytes first(n) gives: its first n bytes, or all of them when there are fewer (it
// is asked again with a larger n when the header promises more). Read as read_pcd reads
// a file: the header from the first MiB, then only as many bytes as it promises. InputError
// naming `name`.
Frame read_pcd_from(const std::string& name,
                    const std::function<const std::string&(std::size_t)>& first,
                    const std::string& label_field = "label");

}  // namespace proxseg::detail
