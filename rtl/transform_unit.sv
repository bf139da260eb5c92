// The transformation unit's matrix step (paper 2.3; units/datapath.h transform_step): per output
// component r, (m_r0 x + m_r1 y) + (m_r2 z + t_r), with t_r = +0 for a direction step
// (translate = 0; the adder still runs, so -0 + +0 = +0 as in the model). One vector per cycle:
//   9 multipliers (LAT_MUL), 6 adders (LAT_ADD), 3 adders (LAT_ADD)
// DEPTH = LAT_MUL + 2 LAT_ADD = 9 with the cycle model's defaults, its transformation_depth().
module transform_unit #(
    parameter int E       = 7,
    parameter int M       = 16,
    parameter bit RNE     = 1'b1,
    parameter bit FLUSH   = 1'b1,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] m00,
    input  logic [E+M:0] m01,
    input  logic [E+M:0] m02,
    input  logic [E+M:0] t0,
    input  logic [E+M:0] m10,
    input  logic [E+M:0] m11,
    input  logic [E+M:0] m12,
    input  logic [E+M:0] t1,
    input  logic [E+M:0] m20,
    input  logic [E+M:0] m21,
    input  logic [E+M:0] m22,
    input  logic [E+M:0] t2,
    input  logic [E+M:0] x,
    input  logic [E+M:0] y,
    input  logic [E+M:0] z,
    input  logic         translate,
    output logic         out_valid,
    output logic [E+M:0] rx,
    output logic [E+M:0] ry,
    output logic [E+M:0] rz
);
  localparam int Depth = LAT_MUL + 2 * LAT_ADD;

  // Rows as packed words: row r = {m_r2, m_r1, m_r0}, its translation (+0 for a direction step).
  localparam int W = E + M + 1;
  logic [3*W-1:0] row[3];
  logic [W-1:0] tr[3];
  logic [W-1:0] r[3];
  assign row[0] = {m02, m01, m00};
  assign row[1] = {m12, m11, m10};
  assign row[2] = {m22, m21, m20};
  assign tr[0] = translate ? t0 : '0;
  assign tr[1] = translate ? t1 : '0;
  assign tr[2] = translate ? t2 : '0;

  /* verilator lint_off UNUSEDSIGNAL */
  logic [17:0] op_valid;  // the operators' own valid bits (the unit's valid is one delay line)
  /* verilator lint_on UNUSEDSIGNAL */

  for (genvar i = 0; i < 3; i++) begin : g_row
    logic [E+M:0] p0, p1, p2, t_d, s01, s2t;
    fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul0 (
        .clk, .rst, .in_valid, .a(row[i][0+:W]), .b(x), .out_valid(op_valid[6*i]), .y(p0)
    );
    fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul1 (
        .clk, .rst, .in_valid, .a(row[i][W+:W]), .b(y), .out_valid(op_valid[6*i+1]), .y(p1)
    );
    fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul2 (
        .clk, .rst, .in_valid, .a(row[i][2*W+:W]), .b(z), .out_valid(op_valid[6*i+2]), .y(p2)
    );
    fp_stage #(.W(E + M + 1), .N(LAT_MUL)) u_t (.clk, .d(tr[i]), .q(t_d));
    fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add01 (
        .clk, .rst, .in_valid, .a(p0), .b(p1), .sub(1'b0), .out_valid(op_valid[6*i+3]), .y(s01)
    );
    fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add2t (
        .clk, .rst, .in_valid, .a(p2), .b(t_d), .sub(1'b0), .out_valid(op_valid[6*i+4]), .y(s2t)
    );
    fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add (
        .clk, .rst, .in_valid, .a(s01), .b(s2t), .sub(1'b0), .out_valid(op_valid[6*i+5]), .y(r[i])
    );
  end

  assign rx = r[0];
  assign ry = r[1];
  assign rz = r[2];
  fp_valid #(.N(Depth)) u_valid (.clk, .rst, .d(in_valid), .q(out_valid));
endmodule
