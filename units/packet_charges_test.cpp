// units::PacketCharges (units/dynrtc_units.h): each cycle shared equally among the packets in
// flight, by hand; the charges add up to the cycles with a packet in flight.
#include <gtest/gtest.h>

#include "units/dynrtc_units.h"

namespace saarcor::units {
namespace {

TEST(PacketCharges, EachCycleSharedAmongThePacketsInFlight) {
  PacketCharges c(3, 2);
  // Cycles 0-1: nothing in flight. Packet 0 on thread 1 from cycle 2, packet 1 on thread 0 from
  // cycle 4: cycles 2-3 are packet 0's alone (2), cycles 4-7 shared by two (2 each).
  c.admit(1, 0, 2);
  c.admit(0, 1, 4);
  c.retire(1, 8);  // packet 0: 2 + 4 / 2 = 4
  EXPECT_DOUBLE_EQ(c.charges()[0], 4.0);
  // Packet 2 takes thread 1 in the cycle packet 0 left it: cycle 8 shared by two again.
  c.admit(1, 2, 8);
  c.retire(0, 9);  // packet 1: 4 / 2 + 1 / 2 = 2.5
  EXPECT_DOUBLE_EQ(c.charges()[1], 2.5);
  c.retire(1, 12);  // packet 2: 1 / 2 + 3 = 3.5
  EXPECT_DOUBLE_EQ(c.charges()[2], 3.5);
  EXPECT_EQ(c.empty_cycles(), 2u);
  EXPECT_EQ(c.last_event(), 12u);
  // 4 + 2.5 + 3.5 = 10: the cycles 2-11, each with a packet in flight.
  EXPECT_DOUBLE_EQ(c.charges()[0] + c.charges()[1] + c.charges()[2], 10.0);
}

TEST(PacketCharges, AGapWithNothingInFlightIsNobodys) {
  PacketCharges c(2, 1);
  c.admit(0, 0, 0);
  c.retire(0, 5);
  c.admit(0, 1, 9);  // cycles 5-8 empty
  c.retire(0, 10);
  EXPECT_DOUBLE_EQ(c.charges()[0], 5.0);
  EXPECT_DOUBLE_EQ(c.charges()[1], 1.0);
  EXPECT_EQ(c.empty_cycles(), 4u);
}

}  // namespace
}  // namespace saarcor::units
