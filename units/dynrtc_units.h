// The units of one DynRTP in the cycle model (paper section 3.1, Figure 2; DESIGN.md section 5):
// traversal, mailboxed list, transformation, intersection, and the ray source (the RGC/RGS in
// front of path a with the hit sink after path g). Each is a CycleUnit (units/cycle_unit.h) with
// its own cache, pipeline depth and rules; units/dynrtp.cpp wires them with the paths a-g.
#pragma once

#include <cstdint>
#include <string>

#include "units/cycle_unit.h"

namespace saarcor::units {

// Traversal unit (paths b, f in; c, g out): one packet-node step per cycle; kd-nodes through the
// traversal cache; the six faces of a box clip issue back to back (D29).
class TraversalUnit : public CycleUnit {
 public:
  TraversalUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth, memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
  bool chains(const Request& done, const Request& next) const override;
};

// Mailboxed list unit (path c in, d out): one list entry per cycle through the list cache; the
// mailbox filter is part of the thread program's list step.
class ListUnit : public CycleUnit {
 public:
  ListUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth, memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
};

// Transformation unit (paths a, d in; b, e out): one matrix-vector step per cycle, n+1 or 2n steps
// per packet (D31); object and triangle matrices arrive as rows through the transformation cache
// (D32); ray generation takes its matrix from the RGS (no fetch).
class TransformationUnit : public CycleUnit {
 public:
  TransformationUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth,
                     memif::Cache& cache);

 protected:
  Fetch fetch(const Request& r) const override;
};

// Intersection unit (path e in, f out): one ray per cycle, P cycles per packet (D30).
class IntersectionUnit : public CycleUnit {
 public:
  IntersectionUnit(hw::Kernel& k, std::string name, ThreadTable& t, int depth);

 protected:
  Fetch fetch(const Request& r) const override;
};

// Ray source and hit sink (path g in, a out): the RGC hands a new primary packet to a free thread,
// one per cycle, only while a thread is free; returning packets run their RGS phases one per cycle
// (shading proper and its memory traffic come with the RGS issue) and free their thread.
class RaySource : public CycleUnit {
 public:
  RaySource(hw::Kernel& k, std::string name, ThreadTable& t, int depth);

  // (Checked before every cycle: no call.)
  bool finished() const { return next_packet_ == packets_ && free_ == threads_.size(); }
  int packets_started() const { return next_packet_; }
  std::uint64_t packets_retired() const { return retired_->value; }

 protected:
  Fetch fetch(const Request& r) const override;
  bool chains(const Request& done, const Request& next) const override;
  void retire(ThreadToken thread) override;
  int extra() override;
  std::uint64_t extra_wakeup(std::uint64_t now) const override;

 private:
  Ring<ThreadToken> free_list_;
  int free_;
  int packets_;
  int next_packet_ = 0;
  hw::Counter* retired_;
  hw::Counter* admitted_;
};

}  // namespace saarcor::units
