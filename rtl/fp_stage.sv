// Pipeline registers of the float operators: delays a data word by N cycles (N = 0 is a wire, so
// a stage boundary can be switched off by a latency parameter). No reset: fp_valid qualifies it.
module fp_stage #(
    parameter int W = 1,
    parameter int N = 1
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input  logic         clk,  // unused when N = 0
    /* verilator lint_on UNUSEDSIGNAL */
    input  logic [W-1:0] d,
    output logic [W-1:0] q
);
  if (N == 0) begin : g_wire
    assign q = d;
  end else begin : g_regs
    logic [W-1:0] r[N];
    always_ff @(posedge clk) begin
      r[0] <= d;
      for (int i = 1; i < N; i++) r[i] <= r[i-1];
    end
    assign q = r[N-1];
  end
endmodule
