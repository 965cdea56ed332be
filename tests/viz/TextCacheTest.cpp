// VTK's text through FreeType's glyph cache, with the library ParcelScope
// gives it (viz/src/TextCache.h): glyphs are loaded once and then served from
// the cache, and text is laid out and drawn as before.
#include <gtest/gtest.h>

#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>

#include <array>
#include <cstring>

#include "TextCache.h"

namespace {

using parcelscope::viz::detail::prepareTextRendering;
using parcelscope::viz::detail::textAllocations;

TEST(TextCache, GlyphsAreLoadedOnceThenServedFromTheCache) {
  prepareTextRendering();
  prepareTextRendering();  // a second call changes nothing
  vtkFreeTypeTools* tools = vtkFreeTypeTools::GetInstance();
  vtkNew<vtkTextProperty> property;
  property->SetFontFamilyToArial();
  property->SetFontSize(23);  // a size no other test of this program uses
  const vtkStdString text = "Parcels: 8,877 (area 436.06 m2)";
  std::array<int, 4> first{}, again{};
  ASSERT_TRUE(tools->GetBoundingBox(property, text, 72, first.data()));
  const std::size_t loaded = textAllocations();
  EXPECT_GT(loaded, 0u) << "the first layout loads its glyphs through the prepared library";
  vtkNew<vtkImageData> image, imageAgain;
  int size[2] = {0, 0}, sizeAgain[2] = {0, 0};
  ASSERT_TRUE(tools->RenderString(property, text, 72, image, size));
  const std::size_t drawn = textAllocations();
  for (int i = 0; i < 200; ++i) {
    ASSERT_TRUE(tools->GetBoundingBox(property, text, 72, again.data()));
    EXPECT_EQ(again, first);
  }
  ASSERT_TRUE(tools->RenderString(property, text, 72, imageAgain, sizeAgain));
  // Laying the text out 200 times more and drawing it again took nothing from
  // FreeType's allocator: every glyph came from the cache.
  EXPECT_EQ(textAllocations(), drawn) << "glyphs were loaded again: the glyph cache dropped them";
  ASSERT_EQ(size[0], sizeAgain[0]);
  ASSERT_EQ(size[1], sizeAgain[1]);
  ASSERT_EQ(image->GetNumberOfPoints(), imageAgain->GetNumberOfPoints());
  EXPECT_EQ(0, std::memcmp(image->GetScalarPointer(), imageAgain->GetScalarPointer(),
                           static_cast<std::size_t>(image->GetNumberOfPoints()) * 4));
}

}  // namespace
