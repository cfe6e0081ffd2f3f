#include "data_loss_report.h"

namespace tilth::tools {

std::string data_loss_report(const std::string& program, const std::vector<DataLoss>& losses) {
  std::string text;
  for (const DataLoss& loss : losses) {
    text += program + ": data lost: node '" + loss.node + "' (" + loss.type +
            "): " + std::to_string(loss.frames) +
            " frame(s) not stored; first report: " + loss.first + "\n";
  }
  return text;
}

}  // namespace tilth::tools
