// A pure SystemVerilog testbench of rtl/'s intersection and transformation datapaths against the
// model's DPI-C reference (docs/dpi.md): a sequencer makes vectors, the drivers put one per cycle
// into each unit (with bubbles), the monitors take each valid output, and the scoreboard checks it
// against the reference's prediction of the same vector (unit_tb_pkg.sv). No C++ harness: run as
// `verilator --binary`, or in any simulator with DPI-C (docs/dpi.md has the commands).
//
// Plusargs: +vectors=N per unit (default 2000), +seed=S. Fault injection, to show a difference is
// caught and named: +flip_unit=intersection|transformation +flip_field=NAME +flip_bit=B
// +flip_vector=K inverts bit B of output NAME (t u v c inside accept | rx ry rz) of the unit's
// K-th output on its way from the RTL to the monitor. The run ends with one summary line, and a
// $fatal (non-zero exit) after any mismatch.
module unit_scoreboard_tb;
  import saarcor_dpi_pkg::*;
  import unit_tb_pkg::*;

  localparam int W = 24;  // fp24: E = 7, M = 16, the units' defaults

  logic clk = 1'b0;
  logic rst = 1'b1;
  initial forever #5 clk = ~clk;

  // ---- the units under test ------------------------------------------------------------------
  logic i_valid = 1'b0, i_out_valid, i_inside, i_accept;
  logic [W-1:0] i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_best_t, i_t, i_u, i_v, i_c;
  logic [31:0] i_inst, i_tri, i_best_inst, i_best_tri;
  intersection_unit u_isect (
      .clk, .rst, .in_valid(i_valid), .ox(i_ox), .oy(i_oy), .oz(i_oz), .dx(i_dx), .dy(i_dy),
      .dz(i_dz), .instance_id(i_inst), .triangle_id(i_tri), .best_t(i_best_t),
      .best_instance(i_best_inst), .best_triangle(i_best_tri), .out_valid(i_out_valid), .t(i_t),
      .u(i_u), .v(i_v), .c(i_c), .hit_inside(i_inside), .accept(i_accept)
  );

  logic x_valid = 1'b0, x_out_valid, x_translate;
  logic [W-1:0] x_m[12];
  logic [W-1:0] x_x, x_y, x_z, x_rx, x_ry, x_rz;
  transform_unit u_xf (
      .clk, .rst, .in_valid(x_valid), .m00(x_m[0]), .m01(x_m[1]), .m02(x_m[2]), .t0(x_m[3]),
      .m10(x_m[4]), .m11(x_m[5]), .m12(x_m[6]), .t1(x_m[7]), .m20(x_m[8]), .m21(x_m[9]),
      .m22(x_m[10]), .t2(x_m[11]), .x(x_x), .y(x_y), .z(x_z), .translate(x_translate),
      .out_valid(x_out_valid), .rx(x_rx), .ry(x_ry), .rz(x_rz)
  );

  // ---- configuration -----------------------------------------------------------------------
  int unsigned vectors = 2000, seed = 1, flip_bit = 0, flip_vector = 0;
  string flip_unit = "", flip_field = "";
  sequencer seq = new;
  scoreboard sb = new;

  initial begin
    void'($value$plusargs("vectors=%d", vectors));
    void'($value$plusargs("seed=%d", seed));
    void'($value$plusargs("flip_unit=%s", flip_unit));
    void'($value$plusargs("flip_field=%s", flip_field));
    void'($value$plusargs("flip_bit=%d", flip_bit));
    void'($value$plusargs("flip_vector=%d", flip_vector));
    void'($urandom(seed));
    if (saarcor_dpi_version() != SAARCOR_DPI_VERSION)
      $fatal(1, "libsaarcor_dpi version %0d, package version %0d", saarcor_dpi_version(),
             SAARCOR_DPI_VERSION);
    no_image_is_an_error();
  end

  // The reference's bad-input path seen from SystemVerilog: the core without a loaded image is
  // an error return and one line, not a crash.
  task automatic no_image_is_an_error();
    /* verilator lint_off UNUSEDSIGNAL */
    int unsigned id, tri_id, t, u, v;  // outputs a failed call leaves alone
    /* verilator lint_on UNUSEDSIGNAL */
    if (saarcor_dpi_trace_pixel(0, 0, 4, id, tri_id, t, u, v) != SAARCOR_DPI_ERROR)
      $fatal(1, "saarcor_dpi_trace_pixel without an image did not fail");
    $display("expected error: %s", saarcor_dpi_last_error());
  endtask

  // The fault injector: the mask of the bit to invert in the named output of the K-th output.
  function automatic logic [31:0] flip(string unit, string name, int unsigned count);
    if (flip_unit == unit && flip_field == name && count == flip_vector) return 32'd1 << flip_bit;
    return '0;
  endfunction

  // ---- drivers: a new vector on most cycles, a bubble on about one in eight -------------------
  int unsigned sent_isect = 0, sent_xf = 0;
  always @(posedge clk) begin
    if (!rst && sent_isect < vectors && $urandom_range(7) != 0) begin
      automatic isect_txn tr = seq.next_isect();
      sb.isect_expected.push_back(tr);
      {i_ox, i_oy, i_oz, i_dx, i_dy, i_dz} <= {tr.ox[W-1:0], tr.oy[W-1:0], tr.oz[W-1:0],
                                               tr.dx[W-1:0], tr.dy[W-1:0], tr.dz[W-1:0]};
      {i_inst, i_tri, i_best_t, i_best_inst, i_best_tri} <=
          {tr.instance_id, tr.triangle_id, tr.best_t[W-1:0], tr.best_instance, tr.best_triangle};
      i_valid <= 1'b1;
      sent_isect <= sent_isect + 1;
    end else begin
      i_valid <= 1'b0;
    end
  end

  always @(posedge clk) begin
    if (!rst && sent_xf < vectors && $urandom_range(7) != 0) begin
      automatic xf_txn tr = seq.next_xf();
      sb.xf_expected.push_back(tr);
      for (int k = 0; k < 12; k++) x_m[k] <= tr.m[k][W-1:0];
      {x_x, x_y, x_z} <= {tr.x[W-1:0], tr.y[W-1:0], tr.z[W-1:0]};
      x_translate <= tr.translate[0];
      x_valid <= 1'b1;
      sent_xf <= sent_xf + 1;
    end else begin
      x_valid <= 1'b0;
    end
  end

  // ---- monitors: every valid output, through the fault injector, to the scoreboard ----------
  int unsigned seen_isect = 0, seen_xf = 0;
  always @(posedge clk) begin
    if (!rst && i_out_valid) begin
      sb.check_isect({8'd0, i_t} ^ flip("intersection", "t", seen_isect),
                     {8'd0, i_u} ^ flip("intersection", "u", seen_isect),
                     {8'd0, i_v} ^ flip("intersection", "v", seen_isect),
                     {8'd0, i_c} ^ flip("intersection", "c", seen_isect),
                     int'({31'd0, i_inside}) ^ int'(flip("intersection", "inside", seen_isect)),
                     int'({31'd0, i_accept}) ^ int'(flip("intersection", "accept", seen_isect)));
      seen_isect <= seen_isect + 1;
    end
    if (!rst && x_out_valid) begin
      sb.check_xf({8'd0, x_rx} ^ flip("transformation", "rx", seen_xf),
                  {8'd0, x_ry} ^ flip("transformation", "ry", seen_xf),
                  {8'd0, x_rz} ^ flip("transformation", "rz", seen_xf));
      seen_xf <= seen_xf + 1;
    end
  end

  // ---- the run: reset, then until every vector has come out (or a stuck pipeline times out) --
  initial begin
    repeat (4) @(posedge clk);
    @(negedge clk) rst = 1'b0;
    for (int unsigned cycle = 0; cycle < 8 * vectors + 100; cycle++) begin
      if (sb.checked_isect == vectors && sb.checked_xf == vectors) break;
      @(posedge clk);
    end
    @(posedge clk);
    $display("SCOREBOARD intersection %0d/%0d vectors (%0d inside, %0d accepted), %s",
             sb.checked_isect, vectors, sb.n_inside, sb.n_accepted,
             $sformatf("transformation %0d/%0d vectors, %0d mismatches", sb.checked_xf, vectors,
                       sb.mismatches));
    if (sb.mismatches != 0 || sb.checked_isect != vectors || sb.checked_xf != vectors)
      $fatal(1, "the RTL differs from the model's DPI-C reference");
    $display("PASS");
    $finish;
  end
endmodule
