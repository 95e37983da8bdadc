#pragma once
// The viewer as one HTML file that needs nothing else (`lumigauss export --format html`): web/viewer/'s page
// with its ES modules bundled into one inline module script, the depth-sorting worker's source as text (the
// page starts it from a blob), the model payload (model_payload.h) in base64 and the scene description
// (scene_info.h), all in `window.__lgEmbedded`. It opens from disk (file://) in any browser with WebGL 2,
// without the lumigauss binary or a server, and relights there under every light the description lists.
//
// The bundler knows exactly the module syntax the viewer uses: one-line `import { a, b } from './x.js';` and
// `export const|let|function|async function|class NAME` at the start of a line. Each module becomes a
// function whose result holds its exports; an import becomes a destructuring of that result. Anything else
// that looks like an import or export is an Error, so a change to the viewer's scripts that the bundler
// would get wrong fails loudly (and tests/fast/viewer_standalone_page_test.cpp with it).
#include <string>
#include <string_view>

namespace lumigauss::view {

// The page. Throws Error when the embedded viewer assets are not what the bundler expects.
std::string standalone_viewer_page(std::string_view model_payload, std::string_view scene_json);

// The viewer's modules from `entry` (e.g. "viewer.js") as one script (exposed for the tests).
std::string bundle_viewer_modules(std::string_view entry);

}  // namespace lumigauss::view
