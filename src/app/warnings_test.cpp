// The black-image heuristic and the error hints (the CLI tests run them end to end).
#include "app/warnings.h"

#include <gtest/gtest.h>

namespace lc::app {
namespace {

io::Image filled(int w, int h, Color c) {
  io::Image img(w, h);
  for (Color& p : img.pixels) p = c;
  return img;
}

TEST(BlackImage, FractionIsJudgedAsDisplayed) {
  io::Image img = filled(10, 10, Color(0.002f));  // clamp: 1/255 (black); sRGB: 7/255 (not)
  EXPECT_EQ(blackFraction(img, io::ToneMap::Clamp, 0), 1.0);
  EXPECT_EQ(blackFraction(img, io::ToneMap::Srgb, 0), 0.0);
  EXPECT_EQ(blackFraction(img, io::ToneMap::Clamp, 3), 0.0);  // 0.016 -> 4/255
  img.at(3, 3) = Color(0, 0, 1);                              // one channel is enough to show
  EXPECT_EQ(blackFraction(img, io::ToneMap::Clamp, 0), 0.99);
}

TEST(BlackImage, ReasonFollowsTheFacts) {
  io::Image black = filled(10, 10, Color(0));
  RenderFacts f{5, 100, 100, 400, 10};
  EXPECT_EQ(blackImageWarning(filled(10, 10, Color(0.5f)), io::ToneMap::Srgb, 0, f), "");
  EXPECT_NE(blackImageWarning(black, io::ToneMap::Srgb, 0, f).find("too weak"), std::string::npos);
  RenderFacts none = f;
  none.lights = 0;
  EXPECT_EQ(blackImageWarning(black, io::ToneMap::Srgb, 0, none), "the image is black: the scene has no lights");
  RenderFacts empty = f;
  empty.shadingPoints = 1;
  EXPECT_NE(blackImageWarning(black, io::ToneMap::Srgb, 0, empty).find("the camera sees almost nothing"),
            std::string::npos);
  // Many camera rays hit something, and almost nothing was shaded: black materials.
  RenderFacts blackSurfaces = empty;
  blackSurfaces.cameraHitFraction = 0.4;
  EXPECT_NE(blackImageWarning(black, io::ToneMap::Srgb, 0, blackSurfaces).find("have black materials"),
            std::string::npos);
  blackSurfaces.cameraHitFraction = 0.01;
  EXPECT_NE(blackImageWarning(black, io::ToneMap::Srgb, 0, blackSurfaces).find("the camera sees almost nothing"),
            std::string::npos);
  RenderFacts shadow = f;
  shadow.occludedRays = 300;
  EXPECT_NE(blackImageWarning(black, io::ToneMap::Srgb, 0, shadow).find("everything is in shadow (75%"),
            std::string::npos);
  // 98% black counts, with the share said; 97% does not.
  io::Image most = black;
  for (int x = 0; x < 2; ++x) most.at(x, 0) = Color(1);
  EXPECT_EQ(blackImageWarning(most, io::ToneMap::Srgb, 0, f).rfind("the image is 98.0% black: ", 0), 0u);
  most.at(2, 0) = Color(1);
  EXPECT_EQ(blackImageWarning(most, io::ToneMap::Srgb, 0, f), "");
}

TEST(MaxCut, WarnsOverATenthOfAPercentOfTheCuts) {
  EXPECT_EQ(maxCutWarning(0, 1000, 4000), "");
  EXPECT_EQ(maxCutWarning(1, 1000, 4000), "");  // 0.1%: not over
  EXPECT_EQ(maxCutWarning(5, 0, 4000), "");
  const std::string w = maxCutWarning(25, 1000, 4000);
  EXPECT_NE(w.find("2.5% of the cuts stopped at --max-cut 4000"), std::string::npos) << w;
  EXPECT_NE(w.find("raise --max-cut"), std::string::npos) << w;
}

TEST(ErrorHints, LenientForUnknownKeywordsOnly) {
  EXPECT_NE(hintForError("unknown keyword 'radius' in sphere").find("--lenient"), std::string::npos);
  EXPECT_EQ(hintForError("expected '=', got '('"), "");
  EXPECT_EQ(hintForError("cannot open 'x.ray': unknown keyword"), "");
}

}  // namespace
}  // namespace lc::app
