#include "server/ui.hpp"

#include <httplib.h>

#include <cstring>

#include "server/ui_assets.hpp"

namespace grip::server {
namespace {

// Everything from this server only; no inline script or style, no frames, no plugins, no
// form posts elsewhere. The page draws with SVG attributes, which CSP leaves alone.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
    "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

const UiAsset* find_asset(const std::string& name) {
  for (std::size_t i = 0; i < kUiAssetCount; ++i)
    if (name == kUiAssets[i].name) return &kUiAssets[i];
  return nullptr;
}

// If-None-Match holds one ETag, a list of them, or "*".
bool etag_matches(const std::string& if_none_match, const char* etag) {
  if (if_none_match.empty()) return false;
  if (if_none_match.find('*') != std::string::npos) return true;
  return if_none_match.find(etag) != std::string::npos;
}

}  // namespace

bool wants_page(const httplib::Request& req) {
  return req.get_header_value("Accept").find("text/html") != std::string::npos;
}

bool is_page_request(const httplib::Request& req) {
  if (req.method != "GET" && req.method != "HEAD") return false;
  return req.path == "/ui" || req.path.rfind("/ui/", 0) == 0 || (req.path == "/" && wants_page(req));
}

bool serve_page_file(const httplib::Request& req, httplib::Response& res, const std::string& name) {
  const UiAsset* asset = find_asset(name);
  if (!asset) return false;
  res.set_header("ETag", asset->etag);
  // The URLs carry no version: the browser revalidates every time and gets a 304 when unchanged.
  res.set_header("Cache-Control", "no-cache");
  res.set_header("Content-Security-Policy", kContentSecurityPolicy);
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  if (etag_matches(req.get_header_value("If-None-Match"), asset->etag)) {
    res.status = 304;
    return true;
  }
  res.status = 200;
  res.set_content(asset->text, std::strlen(asset->text), asset->content_type);
  return true;
}

}  // namespace grip::server
