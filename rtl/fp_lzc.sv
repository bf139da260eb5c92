// Leading-zero count of a W-bit word (W for an all-zero word).
module fp_lzc #(
    parameter int W  = 8,
    parameter int CW = $clog2(W + 1)
) (
    input  logic [ W-1:0] x,
    output logic [CW-1:0] n
);
  always_comb begin
    n = CW'(W);
    for (int i = 0; i < W; i++) if (x[i]) n = CW'(W - 1 - i);
  end
endmodule
