// The intersection unit's datapath (paper 2.1.2; units/datapath.h intersect_unit_triangle and
// accepts), one ray per cycle, as a pipeline of the float operators:
//   t = -O'z / D'z                      divider     LAT_DIV
//   pu = t * D'x, pv = t * D'y           2 multipliers LAT_MUL
//   u = O'x + pu, v = O'y + pv           2 adders    LAT_ADD
//   s = u + v                            adder       LAT_ADD
//   inside, accept                       compare stage LAT_CMP
// DEPTH = LAT_DIV + LAT_MUL + 2 LAT_ADD + LAT_CMP: 8 + 3 + 3 + 3 + 1 = 18 with the cycle model's
// defaults, its intersection_depth(). `hit_inside` (the vectors' `inside`) is the datapath's bit-test acceptance (D'z != 0,
// t > 0, t not inf, u >= 0, v >= 0, u + v >= 0 and <= 1, no NaN: wires on the encodings, no
// comparator). `accept` is `accepts`: inside, and t below the ray's closest hit t_best, or equal
// to it with a smaller (instance, triangle) (the tie rule of docs/shading.md section 3); t and
// t_best are non-negative, so that is a compare of the magnitude bits. The candidate's ids and the
// ray's closest-hit record enter with the ray (the cycle model executes the step on the thread's
// state at issue; nothing else changes the thread's record while it is in this pipeline).
module intersection_unit #(
    parameter int E       = 7,
    parameter int M       = 16,
    parameter bit RNE     = 1'b1,
    parameter bit FLUSH   = 1'b1,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3,
    parameter int LAT_DIV = 8,
    parameter int LAT_CMP = 1,
    parameter int IDW     = 32,
    parameter bit FAULT_STRICT_UV = 1'b0  // tests only: accepts on u + v < 1 instead of <= 1
) (
    input  logic           clk,
    input  logic           rst,
    input  logic           in_valid,
    input  logic [  E+M:0] ox,
    input  logic [  E+M:0] oy,
    input  logic [  E+M:0] oz,
    input  logic [  E+M:0] dx,
    input  logic [  E+M:0] dy,
    input  logic [  E+M:0] dz,
    input  logic [IDW-1:0] instance_id,
    input  logic [IDW-1:0] triangle_id,
    input  logic [  E+M:0] best_t,
    input  logic [IDW-1:0] best_instance,
    input  logic [IDW-1:0] best_triangle,
    output logic           out_valid,
    output logic [  E+M:0] t,
    output logic [  E+M:0] u,
    output logic [  E+M:0] v,
    output logic [  E+M:0] c,
    output logic           hit_inside,
    output logic           accept
);
  localparam int W = E + M + 1;
  localparam int Depth = LAT_DIV + LAT_MUL + 2 * LAT_ADD + LAT_CMP;
  localparam logic [E+M-1:0] InfMag = {{E{1'b1}}, {M{1'b0}}};
  localparam logic [E+M-1:0] OneMag = {1'b0, {(E - 1) {1'b1}}, {M{1'b0}}};

  // The record that travels beside the operators: the candidate's ids and the ray's best hit.
  localparam int RW = 4 * IDW + W;
  logic [RW-1:0] rec0, rec1, rec2, rec3, rec4;
  assign rec0 = {instance_id, triangle_id, best_t, best_instance, best_triangle};

  /* verilator lint_off UNUSEDSIGNAL */
  logic [4:0] op_valid;  // the operators' own valid bits (the unit's valid is one delay line)
  /* verilator lint_on UNUSEDSIGNAL */

  // ---- t = -O'z / D'z ---------------------------------------------------------------------
  logic [E+M:0] t1, ox1, oy1, dx1, dy1, c1;
  fp_div #(.E(E), .M(M), .LAT(LAT_DIV), .RNE(RNE), .FLUSH(FLUSH)) u_div (
      .clk, .rst, .in_valid, .a({~oz[E+M], oz[E+M-1:0]}), .b(dz), .out_valid(op_valid[0]), .y(t1)
  );
  fp_stage #(.W(5 * W + RW), .N(LAT_DIV)) u_d1 (
      .clk, .d({ox, oy, dx, dy, dz, rec0}), .q({ox1, oy1, dx1, dy1, c1, rec1})
  );

  // ---- t * D'x, t * D'y -------------------------------------------------------------------
  logic [E+M:0] pu2, pv2, t2, ox2, oy2, c2;
  fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul_x (
      .clk, .rst, .in_valid, .a(t1), .b(dx1), .out_valid(op_valid[1]), .y(pu2)
  );
  fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul_y (
      .clk, .rst, .in_valid, .a(t1), .b(dy1), .out_valid(op_valid[2]), .y(pv2)
  );
  fp_stage #(.W(4 * W + RW), .N(LAT_MUL)) u_d2 (
      .clk, .d({t1, ox1, oy1, c1, rec1}), .q({t2, ox2, oy2, c2, rec2})
  );

  // ---- u = O'x + t D'x, v = O'y + t D'y ---------------------------------------------------
  logic [E+M:0] u3, v3, t3, c3;
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add_u (
      .clk, .rst, .in_valid, .a(ox2), .b(pu2), .sub(1'b0), .out_valid(op_valid[3]), .y(u3)
  );
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add_v (
      .clk, .rst, .in_valid, .a(oy2), .b(pv2), .sub(1'b0), .out_valid(op_valid[4]), .y(v3)
  );
  fp_stage #(.W(2 * W + RW), .N(LAT_ADD)) u_d3 (.clk, .d({t2, c2, rec2}), .q({t3, c3, rec3}));

  // ---- u + v --------------------------------------------------------------------------------
  logic [E+M:0] s4, t4, u4, v4, c4;
  /* verilator lint_off UNUSEDSIGNAL */
  logic sum_valid;
  /* verilator lint_on UNUSEDSIGNAL */
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add_s (
      .clk, .rst, .in_valid, .a(u3), .b(v3), .sub(1'b0), .out_valid(sum_valid), .y(s4)
  );
  fp_stage #(.W(4 * W + RW), .N(LAT_ADD)) u_d4 (
      .clk, .d({t3, u3, v3, c3, rec3}), .q({t4, u4, v4, c4, rec4})
  );

  // ---- acceptance -------------------------------------------------------------------------
  logic [IDW-1:0] inst4, tri4, best_inst4, best_tri4;
  logic [E+M:0] best_t4;
  assign {inst4, tri4, best_t4, best_inst4, best_tri4} = rec4;

  /* verilator lint_off UNUSEDSIGNAL */
  function automatic logic [E+M-1:0] mag(input logic [E+M:0] x);
    mag = x[E+M-1:0];
  endfunction
  /* verilator lint_on UNUSEDSIGNAL */
  function automatic logic is_nan(input logic [E+M:0] x);
    is_nan = mag(x) > InfMag;
  endfunction
  function automatic logic is_zero(input logic [E+M:0] x);
    is_zero = mag(x) == '0;
  endfunction
  function automatic logic nonneg(input logic [E+M:0] x);  // x >= 0 (-0 too), not NaN
    nonneg = (~x[E+M] | is_zero(x)) & ~is_nan(x);
  endfunction

  logic in4, acc4;
  always_comb begin
    in4 = ~is_zero(c4) & ~is_nan(c4) & ~t4[E+M] & ~is_zero(t4) & ~is_nan(t4) &
          (mag(t4) != InfMag) & nonneg(u4) & nonneg(v4) & nonneg(s4) &
          (FAULT_STRICT_UV ? mag(s4) < OneMag : mag(s4) <= OneMag);
    if (mag(t4) != mag(best_t4)) acc4 = in4 & (mag(t4) < mag(best_t4));
    else if (inst4 != best_inst4) acc4 = in4 & (inst4 < best_inst4);
    else acc4 = in4 & (tri4 < best_tri4);
  end

  fp_stage #(.W(4 * W + 2), .N(LAT_CMP)) u_out (
      .clk, .d({t4, u4, v4, c4, in4, acc4}), .q({t, u, v, c, hit_inside, accept})
  );
  fp_valid #(.N(Depth)) u_valid (.clk, .rst, .d(in_valid), .q(out_valid));
endmodule
