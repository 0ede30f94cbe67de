// The page's own files (src/serve/web/), built into the binary by embed.cmake so that a
// binary serves its page from any working directory and cannot serve another version's.
#pragma once

#include <span>
#include <string_view>

namespace superball::serve {

struct WebAsset {
    std::string_view path;          // "/index.html", "/app.js", ...
    std::string_view content_type;
    std::string_view body;
};

std::span<const WebAsset> web_assets();

}  // namespace superball::serve
