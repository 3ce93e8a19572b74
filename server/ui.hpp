#pragma once
// The browser page (docs/design.md#the-service): GET /ui and /ui/{file}, and GET / when the
// Accept header names text/html. Plain HTML, CSS and JavaScript modules from server/ui/,
// compiled into the binary; no build step, nothing fetched from elsewhere. The page carries
// no data, so it is served without the bearer token; it sends the token (pasted by the user,
// kept in sessionStorage) on its own API calls.
#include <string>

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace grip::server {

// Whether GET / asks for the page rather than the OGC landing document.
bool wants_page(const httplib::Request& req);
// Whether the request is for the page or one of its files (served without the token).
bool is_page_request(const httplib::Request& req);
// Answers with page file `name` ("index.html", "app.js", ...): 200 with ETag, Cache-Control
// and a restrictive Content-Security-Policy, or 304 when If-None-Match names the ETag.
// Returns false (and leaves `res` alone) when there is no such file.
bool serve_page_file(const httplib::Request& req, httplib::Response& res, const std::string& name);

}  // namespace grip::server
