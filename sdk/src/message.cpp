#include "tilth/message.h"

namespace tilth {

Message::~Message() = default;

std::string Message::summary() const { return std::string(type_name()); }

}  // namespace tilth
