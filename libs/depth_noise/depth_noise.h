// How noisy a frame's depths are: the robust standard deviation (1.4826 times the median
// absolute difference, over sqrt 2) of the difference between depth pixels two columns
// apart. Edges between surfaces are a minority of the pairs and move the median little;
// a tilt of a few degrees adds a fraction of a millimetre.
#pragma once

#include <opencv2/core/mat.hpp>

namespace tilth {

// Over every fourth row of `area` of `depth_mm` (CV_32FC1; NaN, infinite or <= 0: no depth); 0 when
// under 100 pairs have depth. A frame whose noise is at most `at_least_mm` gives
// `at_least_mm`, found with one count of the pairs within it (about 10 us for the chain's
// region), without the median's histogram.
float depth_noise_mm(const cv::Mat& depth_mm, const cv::Rect& area, float at_least_mm);

}  // namespace tilth
