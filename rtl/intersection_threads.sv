// The intersection unit of a DynRTP with its thread machinery (paper sections 2.1.2 and 3.1,
// Figure 2 paths e and f; units/intersection_step.h, units/intersection.cpp; D15, D30, D49): the
// thread machinery of rtl/unit_threads.sv around the datapath of rtl/intersection_unit.sv.
//   Arrival (path e, units/boundary_intersection.h): the triangle's rays in unit-triangle space
//   (per lane O', D'), the entry mask, the rays still in the bottom-level list, whether the
//   triangle was the list's last entry, the candidate's instance and triangle ids. Nothing is
//   fetched: the thread is ready at once.
//   Step: P issue cycles, one ray a cycle, lane i in the issue cycle + i, every lane whatever the
//   mask (D30: a masked lane's result is discarded). Each ray's closest hit (t, u, v, c and the
//   ids) is the unit's, per thread and lane: it goes into the datapath with the ray and an
//   accepted candidate replaces it DEPTH cycles later, when it leaves the datapath; a shadow ray
//   that hits is done (any-hit, D15).
//   Output: the thread leaves DEPTH cycles after its last ray went in (its last lane's result
//   leaves the datapath in that cycle and is forwarded), back to the list unit or, when the list
//   is done (the last entry, or every ray of a shadow packet done), to the traversal unit's pop
//   (D49); with it the rays' closest hits (the traversal unit's hit update) and done flags.
//   Side band (path a, two per cycle as the RGS hands them over): a new packet on the thread:
//   its rays' closest hits start afresh (t_best +inf, or 1 - 1/512 for shadow rays; ids none).
module intersection_threads #(
    parameter int THREADS = 16,
    parameter int P       = 4,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3,
    parameter int LAT_DIV = 8,
    parameter int LAT_CMP = 1,
    parameter bit FAULT_STRICT_UV = 1'b0,  // tests only: accepts on u + v < 1
    parameter int TW      = THREADS > 1 ? $clog2(THREADS) : 1
) (
    input  logic                 clk,
    input  logic                 rst,
    // Path e (from the transformation unit). Lane i's O' is in_o[i*72 +: 72] (x, y, z, 24 bits
    // each, x lowest), D' likewise.
    input  logic                 in_valid,
    input  logic [TW-1:0]        in_thread,
    input  logic [P-1:0]         in_mask,
    input  logic [P-1:0]         in_list,
    input  logic                 in_last,
    input  logic [31:0]          in_instance,
    input  logic [31:0]          in_triangle,
    input  logic [P*72-1:0]      in_o,
    input  logic [P*72-1:0]      in_d,
    // Side band: packet starts.
    input  logic [1:0]           st_valid,
    input  logic [2*TW-1:0]      st_thread,
    input  logic [1:0]           st_shadow,
    // Output (path f): dest 0 the list unit, 1 the traversal unit's pop; the rays' records.
    output logic                 out_valid,
    output logic [TW-1:0]        out_thread,
    output logic                 out_dest,
    output logic [P-1:0]         out_mask,
    output logic [P-1:0]         out_done,
    output logic [P*24-1:0]      out_t,
    output logic [P*24-1:0]      out_u,
    output logic [P*24-1:0]      out_v,
    output logic [P*24-1:0]      out_c,
    output logic [P*32-1:0]      out_instance,
    output logic [P*32-1:0]      out_triangle
);
  localparam int W = 24;
  localparam int DEPTH = LAT_DIV + LAT_MUL + 2 * LAT_ADD + LAT_CMP;
  localparam int LW = P > 1 ? $clog2(P) : 1;
  localparam int SW = $clog2(P + 1);
  localparam logic [W-1:0] Inf = 24'h7F0000;        // +inf in fp24 (e7m16)
  localparam logic [W-1:0] ShadowTMax = 24'h3EFF00;  // 1 - 1/512, a shadow ray's t_max

  // ---- per-thread state ------------------------------------------------------------------------
  logic [P-1:0]  mask_r[THREADS], list_r[THREADS], done_r[THREADS];
  logic          last_r[THREADS], shadow_r[THREADS];
  logic [31:0]   inst_r[THREADS], tri_r[THREADS];
  logic [71:0]   o_r[THREADS][P], d_r[THREADS][P];
  logic [W-1:0]  ht[THREADS][P], hu[THREADS][P], hv[THREADS][P], hc[THREADS][P];
  logic [31:0]   hi[THREADS][P], htr[THREADS][P];

  // ---- the thread machinery --------------------------------------------------------------------
  logic iss_valid;
  logic [TW-1:0] iss_thread;
  /* verilator lint_off UNUSEDSIGNAL */
  logic acc_valid, req_valid;
  logic [TW-1:0] acc_thread, req_thread;
  logic [7:0] req_item;
  logic [0:0] out_payload;
  /* verilator lint_on UNUSEDSIGNAL */
  unit_threads #(
      .THREADS(THREADS), .INPUTS(1), .DEPTH(DEPTH), .PW(1), .IW(8), .CW(1), .SW(SW)
  ) threads (
      .clk, .rst, .in_valid, .in_thread,
      .acc_valid, .acc_thread, .acc_first(8'd0), .acc_count(1'b0),
      .req_valid, .req_item, .req_thread, .req_ready(1'b1), .resp_valid(1'b0),
      .resp_thread({TW{1'b0}}),
      .iss_valid, .iss_thread, .iss_steps(SW'(P)), .iss_chain(1'b0), .iss_payload(1'b0),
      .out_valid, .out_thread, .out_payload, .out_ready(1'b1));

  // ---- one ray a cycle into the datapath -------------------------------------------------------
  logic busy;  // lanes 1 .. P-1 of seq_thread go in after its issue cycle
  logic [TW-1:0] seq_thread;
  logic [LW-1:0] seq_lane;
  logic feed;
  logic [TW-1:0] f_thread;
  logic [LW-1:0] f_lane;
  assign feed = iss_valid || busy;
  assign f_thread = iss_valid ? iss_thread : seq_thread;
  assign f_lane = iss_valid ? '0 : seq_lane;

  logic dp_valid, dp_inside, dp_accept;
  logic [W-1:0] dp_t, dp_u, dp_v, dp_c;
  /* verilator lint_off UNUSEDSIGNAL */
  logic dp_inside_unused;
  assign dp_inside_unused = dp_inside;
  /* verilator lint_on UNUSEDSIGNAL */
  intersection_unit #(
      .LAT_ADD(LAT_ADD), .LAT_MUL(LAT_MUL), .LAT_DIV(LAT_DIV), .LAT_CMP(LAT_CMP),
      .FAULT_STRICT_UV(FAULT_STRICT_UV)
  ) datapath (
      .clk, .rst, .in_valid(feed),
      .ox(o_r[f_thread][f_lane][0+:W]), .oy(o_r[f_thread][f_lane][W+:W]),
      .oz(o_r[f_thread][f_lane][2*W+:W]),
      .dx(d_r[f_thread][f_lane][0+:W]), .dy(d_r[f_thread][f_lane][W+:W]),
      .dz(d_r[f_thread][f_lane][2*W+:W]),
      .instance_id(inst_r[f_thread]), .triangle_id(tri_r[f_thread]),
      .best_t(ht[f_thread][f_lane]), .best_instance(hi[f_thread][f_lane]),
      .best_triangle(htr[f_thread][f_lane]),
      .out_valid(dp_valid), .t(dp_t), .u(dp_u), .v(dp_v), .c(dp_c), .hit_inside(dp_inside),
      .accept(dp_accept));

  // The ray's thread and lane beside the datapath.
  logic [TW-1:0] wb_thread;
  logic [LW-1:0] wb_lane;
  fp_stage #(.W(TW + LW), .N(DEPTH)) u_tag (
      .clk, .d({f_thread, f_lane}), .q({wb_thread, wb_lane}));
  logic wb;  // an entering ray's candidate replaces its closest hit
  assign wb = dp_valid && dp_accept && mask_r[wb_thread][wb_lane];

  // ---- output: the leaving thread's records, its last lane forwarded from the datapath ---------
  logic [P-1:0] done_out, list_out;
  always_comb begin
    done_out = done_r[out_thread];
    for (int i = 0; i < P; i++) begin
      logic fwd;
      fwd = wb && wb_thread == out_thread && wb_lane == LW'(i);
      out_t[i*W+:W] = fwd ? dp_t : ht[out_thread][i];
      out_u[i*W+:W] = fwd ? dp_u : hu[out_thread][i];
      out_v[i*W+:W] = fwd ? dp_v : hv[out_thread][i];
      out_c[i*W+:W] = fwd ? dp_c : hc[out_thread][i];
      out_instance[i*32+:32] = fwd ? inst_r[out_thread] : hi[out_thread][i];
      out_triangle[i*32+:32] = fwd ? tri_r[out_thread] : htr[out_thread][i];
      if (fwd && shadow_r[out_thread]) done_out[i] = 1'b1;
    end
    // Any-hit rays that are done leave the list (ListStep::resume).
    list_out = shadow_r[out_thread] ? list_r[out_thread] & ~done_out : list_r[out_thread];
  end
  assign out_done = done_out;
  assign out_mask = list_out;
  assign out_dest = last_r[out_thread] || list_out == '0;

  always_ff @(posedge clk) begin
    if (rst) begin
      busy <= 1'b0;
    end else begin
      if (iss_valid) begin
        seq_thread <= iss_thread;
        seq_lane <= LW'(1);
        busy <= P > 1;
      end else if (busy) begin
        seq_lane <= seq_lane + LW'(1);
        busy <= 32'(seq_lane) + 1 < P;
      end
      if (wb) begin
        ht[wb_thread][wb_lane] <= dp_t;
        hu[wb_thread][wb_lane] <= dp_u;
        hv[wb_thread][wb_lane] <= dp_v;
        hc[wb_thread][wb_lane] <= dp_c;
        hi[wb_thread][wb_lane] <= inst_r[wb_thread];
        htr[wb_thread][wb_lane] <= tri_r[wb_thread];
        if (shadow_r[wb_thread]) done_r[wb_thread][wb_lane] <= 1'b1;
      end
      for (int s = 0; s < 2; s++)
        if (st_valid[s]) begin
          shadow_r[st_thread[s*TW+:TW]] <= st_shadow[s];
          done_r[st_thread[s*TW+:TW]] <= '0;
          for (int i = 0; i < P; i++) begin
            ht[st_thread[s*TW+:TW]][i] <= st_shadow[s] ? ShadowTMax : Inf;
            hu[st_thread[s*TW+:TW]][i] <= '0;
            hv[st_thread[s*TW+:TW]][i] <= '0;
            hc[st_thread[s*TW+:TW]][i] <= '0;
            hi[st_thread[s*TW+:TW]][i] <= '1;
            htr[st_thread[s*TW+:TW]][i] <= '1;
          end
        end
      if (in_valid) begin
        mask_r[in_thread] <= in_mask;
        list_r[in_thread] <= in_list;
        last_r[in_thread] <= in_last;
        inst_r[in_thread] <= in_instance;
        tri_r[in_thread] <= in_triangle;
        for (int i = 0; i < P; i++) begin
          o_r[in_thread][i] <= in_o[i*72+:72];
          d_r[in_thread][i] <= in_d[i*72+:72];
        end
      end
    end
  end
endmodule
