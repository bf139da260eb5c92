// Test top: every operator of one format and mode side by side on the same operand stream
// (rtl/fp_ops_test.cpp drives it against fixedfloat). The latency defaults are the cycle model's
// (units/cycle_params.cpp: lat.add 3, lat.mul 3, lat.div 8, lat.cmp 1).
module fp_ops_top #(
    parameter int E       = 7,
    parameter int M       = 16,
    parameter bit RNE     = 1'b1,
    parameter bit FLUSH   = 1'b1,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3,
    parameter int LAT_DIV = 8,
    parameter int LAT_CMP = 1
) (
    input  logic         clk,
    input  logic         rst,
    input  logic         in_valid,
    input  logic [E+M:0] a,
    input  logic [E+M:0] b,
    output logic         add_valid,
    output logic [E+M:0] add_y,
    output logic         sub_valid,
    output logic [E+M:0] sub_y,
    output logic         mul_valid,
    output logic [E+M:0] mul_y,
    output logic         div_valid,
    output logic [E+M:0] div_y,
    output logic         cmp_valid,
    output logic         lt,
    output logic         le,
    output logic         eq,
    output logic         min_valid,
    output logic [E+M:0] min_y,
    output logic         max_valid,
    output logic [E+M:0] max_y
);
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_add (
      .clk, .rst, .in_valid, .a, .b, .sub(1'b0), .out_valid(add_valid), .y(add_y)
  );
  fp_add #(.E(E), .M(M), .LAT(LAT_ADD), .RNE(RNE), .FLUSH(FLUSH)) u_sub (
      .clk, .rst, .in_valid, .a, .b, .sub(1'b1), .out_valid(sub_valid), .y(sub_y)
  );
  fp_mul #(.E(E), .M(M), .LAT(LAT_MUL), .RNE(RNE), .FLUSH(FLUSH)) u_mul (
      .clk, .rst, .in_valid, .a, .b, .out_valid(mul_valid), .y(mul_y)
  );
  fp_div #(.E(E), .M(M), .LAT(LAT_DIV), .RNE(RNE), .FLUSH(FLUSH)) u_div (
      .clk, .rst, .in_valid, .a, .b, .out_valid(div_valid), .y(div_y)
  );
  fp_cmp #(.E(E), .M(M), .LAT(LAT_CMP), .FLUSH(FLUSH)) u_cmp (
      .clk, .rst, .in_valid, .a, .b, .out_valid(cmp_valid), .lt, .le, .eq
  );
  fp_minmax #(.E(E), .M(M), .LAT(LAT_CMP), .FLUSH(FLUSH), .MAX(1'b0)) u_min (
      .clk, .rst, .in_valid, .a, .b, .out_valid(min_valid), .y(min_y)
  );
  fp_minmax #(.E(E), .M(M), .LAT(LAT_CMP), .FLUSH(FLUSH), .MAX(1'b1)) u_max (
      .clk, .rst, .in_valid, .a, .b, .out_valid(max_valid), .y(max_y)
  );
endmodule
