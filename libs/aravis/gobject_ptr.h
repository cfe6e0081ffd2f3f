// Ownership of Aravis (GObject) objects and errors in C++: one reference held by a
// unique_ptr, and a GError turned into a tilth::Error that says what was being done.
#pragma once

#include <memory>
#include <string>

#include <arv.h>

#include "tilth/error.h"

namespace tilth::aravis {

struct GObjectUnref {
  void operator()(gpointer object) const { g_object_unref(object); }
};
template <class T>
using GObjectPtr = std::unique_ptr<T, GObjectUnref>;

// Collects a GError from one Aravis call: `aravis_call(..., error.out()); error.check("...")`.
class GErrorSlot {
 public:
  GErrorSlot() = default;
  GErrorSlot(const GErrorSlot&) = delete;
  GErrorSlot& operator=(const GErrorSlot&) = delete;
  ~GErrorSlot() { clear(); }

  GError** out() {
    clear();
    return &error_;
  }
  bool failed() const { return error_ != nullptr; }
  std::string message() const { return error_ != nullptr ? error_->message : ""; }
  void clear() { g_clear_error(&error_); }
  // Throws tilth::Error("<doing>: <Aravis's message>") when the call failed.
  void check(const std::string& doing) {
    if (error_ == nullptr) return;
    const std::string text = doing + ": " + message();
    clear();
    throw Error(text);
  }

 private:
  GError* error_ = nullptr;
};

}  // namespace tilth::aravis
