#include "tilth/message_pool.h"

namespace tilth {

void reuse_or_create(cv::Mat& image, int rows, int cols, int type) {
  if (image.u != nullptr && image.u->refcount > 1) image.release();  // someone kept it
  image.create(rows, cols, type);
}

}  // namespace tilth
