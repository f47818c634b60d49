// The HTML page writer (common/html.h): escaping, base64 against the RFC 4648 test vectors, a well-formed document.
#include "common/html.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "tests/recording/temp_dir.h"
#include "tests/support/html_check.h"

namespace roamlab::html {
namespace {

using ::roamlab::testing::CheckHtml;
using ::roamlab::testing::DecodeBase64;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(HtmlTest, Base64MatchesTheRfcVectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
}

TEST(HtmlTest, Base64RoundTripsEveryByte) {
  std::string bytes;
  for (int i = 0; i < 256; ++i) bytes += static_cast<char>(i);
  for (std::size_t n = 250; n <= 256; ++n) EXPECT_EQ(DecodeBase64(Base64(bytes.substr(0, n))), bytes.substr(0, n));
  EXPECT_FALSE(DecodeBase64("Zg=").has_value());
  EXPECT_FALSE(DecodeBase64("Z=g=").has_value());
  EXPECT_FALSE(DecodeBase64("Zm9v!A==").has_value());
}

TEST(HtmlTest, EscapesMarkup) { EXPECT_EQ(Escape("a<b & \"c\" > 'd'"), "a&lt;b &amp; &quot;c&quot; &gt; &#39;d&#39;"); }

TEST(HtmlTest, PageIsWellFormedWithTablesAndEmbeddedImages) {
  roamlab::testing::TempDir dir;
  const std::string png = dir.File("figure.png");
  const std::string bytes = std::string("\x89PNG\r\n\x1a\n", 8) + std::string(100, '\0') + "tail";
  std::ofstream(png, std::ios::binary) << bytes;
  Page page("Title <with> markup");
  page.Heading(2, "Section & more");
  page.Paragraph("x < y", "headline");
  page.AddTable({{"name", "value <m>"}, {{"a", "1"}, {"<script>", "2"}}});
  ASSERT_TRUE(page.AddImage(png, "a figure").ok());
  EXPECT_FALSE(page.AddImage(dir.File("missing.png"), "missing").ok());
  const std::string document = page.Document();
  const auto summary = CheckHtml(document);
  ASSERT_EQ(summary.error, "") << document;
  ASSERT_EQ(summary.table_headers.size(), 1u);
  EXPECT_THAT(summary.table_headers[0], ElementsAre("name", "value &lt;m&gt;"));
  ASSERT_EQ(summary.image_sources.size(), 1u);
  const std::string prefix = "data:image/png;base64,";
  ASSERT_EQ(summary.image_sources[0].rfind(prefix, 0), 0u);
  EXPECT_EQ(DecodeBase64(summary.image_sources[0].substr(prefix.size())), bytes);
  EXPECT_THAT(document, HasSubstr("&lt;script&gt;"));
  EXPECT_EQ(document.find("<script"), std::string::npos);
}

TEST(HtmlTest, CheckerFindsUnclosedAndMisnestedTags) {
  EXPECT_NE(CheckHtml("<html><body><p>x</body></html>").error, "");
  EXPECT_NE(CheckHtml("<table><tr><td>x</td></table>").error, "");
  EXPECT_NE(CheckHtml("<p>a < b</p>").error, "");
  EXPECT_EQ(CheckHtml("<p>a<img src=\"x\"><br/></p>").error, "");
}

}  // namespace
}  // namespace roamlab::html
