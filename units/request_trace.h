// The request trace (docs/traces.md): one text line per thread-program request a unit served, with
// the datapath transactions the request made as hex encodings of the model's float format. The
// cycle model writes a line when a unit issues the request (cycle, DynRTP, thread:
// units/run_trace.h), the functional model one per request of each packet in turn (no cycle). A
// request is named by its primary packet (the RGC's packet index: the pixels, whichever thread
// runs it) and its position in that packet's request sequence; under that key both models write
// the same lines (testbench/trace_test.cpp).
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "memif/image_format.h"
#include "units/program_types.h"

namespace saarcor::units {

// The first line of a trace file: the format and its columns.
inline constexpr const char* kTraceHeader =
    "# saarcor-trace 1: cycle dynrtp thread packet seq unit phase item steps mask kind txn...";
inline constexpr std::uint64_t kNoCycle = std::numeric_limits<std::uint64_t>::max();

// One line. Columns are separated by one space; an absent value is '-'.
struct TraceLine {
  std::uint64_t cycle = kNoCycle;  // the issue cycle; kNoCycle ('-'): the functional model
  int dynrtp = -1;                 // -1 ('-'): the functional model
  int thread = -1;                 // the DynRTP thread id (global over pipelines); -1: functional
  int packet = 0;                  // primary packet index
  std::uint32_t seq = 0;           // the request's position in its packet's sequence (0 first)
  UnitId unit = UnitId::kNone;
  Phase phase = Phase::kDone;
  std::uint32_t item = memif::kNone;  // memif::kNone ('-'): the request names no item
  int steps = 0;
  std::uint64_t mask = 0;  // the rays concerned (hex)
  RayKind kind = RayKind::kPrimary;
  std::string txn;  // the transactions, tokens separated by one space; empty ('-'): none
  friend bool operator==(const TraceLine&, const TraceLine&) = default;
};
// The line without its newline.
std::string format_trace_line(const TraceLine& line);
// Throws std::runtime_error ("trace line: ...") for a line that is not one.
TraceLine parse_trace_line(const std::string& text);
// The comparison key's values of a line: everything but cycle, dynrtp and thread.
bool same_request(const TraceLine& a, const TraceLine& b);

// What a thread executed last, as the trace names it (the cycle model's thread table keeps it for
// a traced run).
struct TracedStep {
  int packet = -1;
  std::uint32_t seq = 0;
  std::uint64_t mask = 0;
  RayKind kind = RayKind::kPrimary;
  std::string txn;
};

// Appends `digits` hex digits of `bits`.
void append_hex(std::string& s, std::uint64_t bits, int digits);

// The transactions of one request as trace tokens (docs/traces.md), inputs '->' outputs:
//   traversal       L<lane>=split,o,d,tn,tf->near,far,near_tf,far_tn
//   transformation  M=m00,m01,m02,t0,m10,m11,m12,t1,m20,m21,m22,t2 (when the matrix changes), then
//                   L<lane>.o=x,y,z->x,y,z (a point: translated), L<lane>.d=... (a direction),
//                   S.o=... (a shared origin: one step for the packet)
//   intersection    L<lane>=ox,oy,oz,dx,dy,dz->t,u,v,c,inside
template <class F>
class TraceTap final : public UnitTap<F> {
 public:
  static constexpr int kDigits = (1 + F::kExpBits + F::kManBits + 3) / 4;

  // Starts a request: no tokens, no matrix printed yet.
  void begin() {
    text_.clear();
    have_m_ = false;
  }
  std::string take() { return std::move(text_); }

  void traversal(int lane, F split, F o_axis, F d_axis, F tn, F tf, bool go_near, bool go_far,
                 F near_tf, F far_tn) override {
    token_lane(lane, "");
    values({split, o_axis, d_axis, tn, tf});
    text_ += "->";
    text_ += go_near ? "1," : "0,";
    text_ += go_far ? "1," : "0,";
    values({near_tf, far_tn});
  }
  void transformation(int lane, const Mat34<F>& m, const Vec3<F>& in, bool translate,
                      const Vec3<F>& out) override {
    if (!have_m_ || !(m == m_)) {
      m_ = m;
      have_m_ = true;
      token_lane(-2, "");
      values({m[0][0], m[0][1], m[0][2], m[0][3], m[1][0], m[1][1], m[1][2], m[1][3], m[2][0],
              m[2][1], m[2][2], m[2][3]});
    }
    token_lane(lane, translate ? ".o" : ".d");
    values({in[0], in[1], in[2]});
    text_ += "->";
    values({out[0], out[1], out[2]});
  }
  void intersection(int lane, const Ray<F>& ray, const Candidate<F>& c) override {
    token_lane(lane, "");
    values({ray.o[0], ray.o[1], ray.o[2], ray.d[0], ray.d[1], ray.d[2]});
    text_ += "->";
    values({c.t, c.u, c.v, c.c});
    text_ += c.inside ? ",1" : ",0";
  }

 private:
  // "L<lane><suffix>=", "S<suffix>=" (lane -1) or "M=" (lane -2), after a space between tokens.
  void token_lane(int lane, const char* suffix) {
    if (!text_.empty()) text_ += ' ';
    if (lane == -2) {
      text_ += "M=";
      return;
    }
    if (lane < 0) {
      text_ += 'S';
    } else {
      text_ += 'L';
      text_ += std::to_string(lane);
    }
    text_ += suffix;
    text_ += '=';
  }
  void values(std::initializer_list<F> v) {
    bool first = true;
    for (const F x : v) {
      if (!first) text_ += ',';
      first = false;
      append_hex(text_, x.bits, kDigits);
    }
  }

  std::string text_;
  Mat34<F> m_{};
  bool have_m_ = false;
};

}  // namespace saarcor::units
