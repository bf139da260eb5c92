// One ray's lane of the traversal unit's kd-node step (paper 3.1; units/datapath.h
// traversal_lane): d = (split - O[axis]) / D[axis]; the ray segment [tn, tf] needs the near child
// unless d < tn and the far child unless tf < d; the near child's segment ends at d, the far
// child's starts there, except for a NaN d (a bit test), which keeps [tn, tf] on both sides.
//   adder (subtract) LAT_ADD, divider LAT_DIV, two comparators LAT_CMP
// DEPTH = LAT_ADD + LAT_DIV + LAT_CMP = 3 + 8 + 1 = 12 with the cycle model's defaults, its
// traversal_depth().
module traversal_unit #(
    parameter int E       = 7,
    parameter int M       = 16,
    parameter bit RNE     = 1'b1,
    parameter bit FLUSH   = 1'b1,
    parameter int LAT_ADD = 3,
    parameter int LAT_DIV = 8,
    parameter int LAT_CMP = 1
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] split,
    input  logic [E+M:0] o_axis,
    input  logic [E+M:0] d_axis,
    input  logic [E+M:0] tn,
    input  logic [E+M:0] tf,
    output logic         out_valid,
    output logic         go_near,
    output logic         go_far,
    output logic [E+M:0] near_tf,
    output logic [E+M:0] far_tn
);
  localparam int W = E + M + 1;
  localparam int Depth = LAT_ADD + LAT_DIV + LAT_CMP;
  localparam logic [E+M-1:0] InfMag = {{E{1'b1}}, {M{1'b0}}};

  /* verilator lint_off UNUSEDSIGNAL */
  logic [1:0] op_valid;
  logic eq_before, eq_after;
  logic [E+M:0] f0, f1, f2, f3;
  /* verilator lint_on UNUSEDSIGNAL */

  logic [E+M:0] diff1, d_axis1, tn1, tf1;
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_sub (
      .clk, .rst, .in_valid, .a(split), .b(o_axis), .sub(1'b1), .out_valid(op_valid[0]), .y(diff1)
  );
  fp_stage #(.W(3 * W), .N(LAT_ADD)) u_d1 (.clk, .d({d_axis, tn, tf}), .q({d_axis1, tn1, tf1}));

  logic [E+M:0] d2, tn2, tf2;
  fp_div #(.E(E), .M(M), .LAT(LAT_DIV), .RNE(RNE), .FLUSH(FLUSH)) u_div (
      .clk, .rst, .in_valid, .a(diff1), .b(d_axis1), .out_valid(op_valid[1]), .y(d2)
  );
  fp_stage #(.W(2 * W), .N(LAT_DIV)) u_d2 (.clk, .d({tn1, tf1}), .q({tn2, tf2}));

  logic ahead, beyond, nan, near, far;
  fp_cmp_core #(.E(E), .M(M), .FLUSH(FLUSH)) u_before (
      .a(d2), .b(tn2), .lt(ahead), .eq(eq_before), .fa(f0), .fb(f1)
  );
  fp_cmp_core #(.E(E), .M(M), .FLUSH(FLUSH)) u_after (
      .a(tf2), .b(d2), .lt(beyond), .eq(eq_after), .fa(f2), .fb(f3)
  );
  assign nan  = d2[E+M-1:0] > InfMag;
  assign near = ~ahead;
  assign far  = ~beyond;
  fp_stage #(.W(2 + 2 * W), .N(LAT_CMP)) u_out (
      .clk,
      .d({near, far, (far & ~nan) ? d2 : tf2, (near & ~nan) ? d2 : tn2}),
      .q({go_near, go_far, near_tf, far_tn})
  );
  fp_valid #(.N(Depth)) u_valid (.clk, .rst, .d(in_valid), .q(out_valid));
endmodule
