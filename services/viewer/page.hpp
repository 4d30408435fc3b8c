#pragma once
// The viewer's page (page/index.html), embedded at build time.
namespace nudge::viewer_service {
extern const char* const kIndexHtml;
}
