// viewer/url_path.h: the viewer's request targets are decoded so that nothing outside the served content can
// be named (traversal, encoded separators, NUL, absolute forms are refused).
#include <gtest/gtest.h>

#include <string>

#include "lumigauss/viewer/url_path.h"

namespace lumigauss::view {
namespace {

TEST(ViewUrlPath, AcceptsPlainNamesAndSplitsTheQuery) {
    const auto root = parse_request_target("/");
    ASSERT_TRUE(root);
    EXPECT_EQ(root->path, "");
    const auto js = parse_request_target("/viewer.js?bench=20&cam=1,2");
    ASSERT_TRUE(js);
    EXPECT_EQ(js->path, "viewer.js");
    EXPECT_EQ(js->query, "bench=20&cam=1,2");
    const auto nested = parse_request_target("/a/b%20c.js");
    ASSERT_TRUE(nested);
    EXPECT_EQ(nested->path, "a/b c.js");
}

TEST(ViewUrlPath, RefusesTraversalAndEncodedSeparators) {
    const std::string refused[] = {
        "/..",
        "/../etc/passwd",
        "/a/../../etc/passwd",
        "/%2e%2e/etc/passwd",
        "/%2E%2E/etc/passwd",
        "/.%2e/x",
        "/%2e./x",
        "//etc/passwd",
        "/a//b",
        "/a%2fb",
        "/a%2F..%2Fb",
        "/a%5cb",
        "/a\\b",
        "/x%00",
        "/%00",
        "/.",
        "/./index.html",
        "/.hidden",
        "/a/",
        "/%252e%252e/x",
        "/%zz",
        "/%2",
        "/a b",
        "/a\tb",
        "/\xc3\xa9",
        "/%c3%a9",
        "/a#frag",
        "etc/passwd",
        "",
        "*",
        "http://127.0.0.1/index.html",
        "/%0d%0aSet-Cookie:x",
    };
    for (const std::string& t : refused) EXPECT_FALSE(parse_request_target(t)) << t;
    EXPECT_FALSE(parse_request_target(std::string("/x\0y", 4)));
    EXPECT_FALSE(parse_request_target("/" + std::string(kMaxPathBytes, 'a')));
}

TEST(ViewUrlPath, QueryDecodingIsFormEncoding) {
    const auto q = parse_query("a=1&b=x%20y+z&flag&a=2&&data=%7B%22k%22%3A1%7D");
    ASSERT_TRUE(q);
    EXPECT_EQ(q->at("a"), "2");
    EXPECT_EQ(q->at("b"), "x y z");
    EXPECT_EQ(q->at("flag"), "");
    EXPECT_EQ(q->at("data"), "{\"k\":1}");
    EXPECT_FALSE(parse_query("a=%zz"));
    EXPECT_FALSE(parse_query("a=%00"));
    EXPECT_FALSE(percent_decode("%4", false));
    EXPECT_EQ(percent_decode("a+b", false).value(), "a+b");
}

}  // namespace
}  // namespace lumigauss::view
