// What every DPI-C entry point of rtl/dpi/ shares: exceptions never cross the C ABI into the
// simulator; each call runs its body under guarded(), which turns any failure into
// SAARCOR_DPI_ERROR and the one line saarcor_dpi_last_error() returns.
#pragma once

#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

#include "fixedfloat/format.h"
#include "rtl/dpi/saarcor_dpi.h"

namespace saarcor::dpi {

void set_last_error(const std::string& message);

template <class Body>
int guarded(const char* function, Body&& body) {
  try {
    body();
    return SAARCOR_DPI_OK;
  } catch (const std::exception& e) {
    set_last_error(std::string(function) + ": " + e.what());
  } catch (...) {
    set_last_error(std::string(function) + ": unknown failure");
  }
  return SAARCOR_DPI_ERROR;
}

// A null output pointer is the caller's bug; say which.
template <class T>
T& out(T* p, const char* name) {
  if (p == nullptr) throw std::invalid_argument(std::string("output '") + name + "' is null");
  return *p;
}

// An encoding that must fit `f`'s bits.
std::uint32_t operand(unsigned int bits, const ff::Format& f, const char* name);

}  // namespace saarcor::dpi
