// The valid bit beside fp_stage: delayed by N cycles (N = 0: a wire), synchronous reset.
module fp_valid #(
    parameter int N = 1
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input  logic clk,  // unused when N = 0
    input  logic rst,
    /* verilator lint_on UNUSEDSIGNAL */
    input  logic d,
    output logic q
);
  if (N == 0) begin : g_wire
    assign q = d;
  end else begin : g_regs
    logic [N-1:0] r;
    always_ff @(posedge clk) begin
      if (rst) r <= '0;
      else r <= N'({r, d});
    end
    assign q = r[N-1];
  end
endmodule
