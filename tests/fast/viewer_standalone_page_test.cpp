// The self-contained viewer page (viewer/standalone_page.h) and base64 (util/base64.h), without a browser:
// the browser test (CliViewBrowser.ExportedPageWorksFromDiskAlone) opens the page.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>

#include "lumigauss/util/base64.h"
#include "lumigauss/viewer/standalone_page.h"

namespace lumigauss {
namespace {

TEST(Base64, Rfc4648TestVectors) {
    EXPECT_EQ(base64_encode(""), "");
    EXPECT_EQ(base64_encode("f"), "Zg==");
    EXPECT_EQ(base64_encode("fo"), "Zm8=");
    EXPECT_EQ(base64_encode("foo"), "Zm9v");
    EXPECT_EQ(base64_encode("foob"), "Zm9vYg==");
    EXPECT_EQ(base64_encode("fooba"), "Zm9vYmE=");
    EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
    EXPECT_EQ(base64_encode(std::string("\xff\xfe\x00\x01", 4)), "//4AAQ==");
}

// Every module once, each after the modules it imports, and no module syntax left.
TEST(ViewerStandalonePage, BundleHasEveryModuleInOrderAndNoModuleSyntax) {
    const std::string bundle = view::bundle_viewer_modules("viewer.js");
    const auto at = [&](const std::string& file) {
        const std::size_t p = bundle.find("// ---- " + file + "\n");
        EXPECT_NE(p, std::string::npos) << file;
        EXPECT_EQ(bundle.find("// ---- " + file + "\n", p + 1), std::string::npos) << file << " twice";
        return p;
    };
    EXPECT_LT(at("sh.js"), at("shaders.js"));
    EXPECT_LT(at("shaders.js"), at("renderer.js"));
    EXPECT_LT(at("sh.js"), at("model.js"));
    for (const char* dep : {"model.js", "orbit.js", "renderer.js", "shaders.js", "sh.js"})
        EXPECT_LT(at(dep), at("viewer.js")) << dep;
    EXPECT_EQ(bundle.find("sort_worker.js\n"), std::string::npos) << "the worker is not a module of the page";
    std::istringstream lines(bundle);
    const std::regex module_syntax(R"(^\s*(import|export)\b)");
    for (std::string line; std::getline(lines, line);)
        EXPECT_FALSE(std::regex_search(line, module_syntax)) << line;
    // An import became a destructuring of the imported module's exports.
    EXPECT_NE(bundle.find("const { Y00 } = __lg_sh_js;"), std::string::npos);
    EXPECT_NE(bundle.find("return { Y00, Y1, Y2, Y20, Y22,"), std::string::npos);
}

TEST(ViewerStandalonePage, HoldsTheModelTheSceneAndTheWorker) {
    const std::string payload("LGVIEW01\x01\x00\x00\x00", 12);
    // A light name that would end a <script> element if written as it is.
    const std::string scene = R"({"lights": [{"name": "</script><b>x"}]})";
    const std::string page = view::standalone_viewer_page(payload, scene);
    EXPECT_EQ(page.rfind("<!doctype html>", 0), 0u);
    EXPECT_NE(page.find("window.__lgEmbedded"), std::string::npos);
    EXPECT_NE(page.find("model: \"" + base64_encode(payload) + "\""), std::string::npos);
    EXPECT_NE(page.find(R"("name": "\u003c/script>\u003cb>x")"), std::string::npos);
    EXPECT_EQ(page.find("</script><b>"), std::string::npos);
    EXPECT_NE(page.find("sortWorker: \""), std::string::npos);
    EXPECT_NE(page.find("self.onmessage"), std::string::npos) << "the worker's source is missing";
    EXPECT_EQ(page.find("src=\"viewer.js\""), std::string::npos) << "the page still loads a file";
    EXPECT_NE(page.find("<script type=\"module\">"), std::string::npos);
}

}  // namespace
}  // namespace lumigauss
