#pragma once
// Internal to server/ui.cpp: the files of server/ui/, compiled into the server by
// server/ui/embed_ui.cmake (the generated source defines these).
#include <cstddef>

namespace grip::server {

struct UiAsset {
  const char* name;          // "app.js"
  const char* content_type;  // "text/javascript; charset=utf-8"
  const char* etag;          // quoted SHA-256 prefix of the file
  const char* text;
};

extern const UiAsset kUiAssets[];
extern const std::size_t kUiAssetCount;

}  // namespace grip::server
