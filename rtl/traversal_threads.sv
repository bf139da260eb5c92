// The traversal unit with the thread machinery it has in the cycle model (units/traversal.cpp,
// units/cycle_unit.h; docs/cycle-model.md "Units"): rtl/unit_threads.sv accepts one thread per
// cycle from the input paths in D25's priority order (own loop, f, list -> traversal, RGS ->
// traversal, b), fetches a node step's kd-node through the traversal cache (a clip face or a pop
// fetches nothing), keeps ready threads in data-arrival order and issues one per cycle, the clip
// faces chained back to back (D29); rtl/traversal_ctrl.sv computes the request and says where the
// thread goes DEPTH cycles later: its own loop (back into the input paths), the list unit (path c:
// a leaf's list, or the top level's list after an object) or the RGS (path g). unit_threads'
// own delivery is not used (the thread's path is known only at the end of the datapath).
//
// A thread arriving on f or list -> traversal pops (docs/hw-interface.md: the model pops in the
// list and intersection units; here the thread passes through the traversal unit for it).
// Test-only faults (0 in every real build): FAULT_PRIO_SWAP swaps the priorities of f and b;
// FAULT_POP_OFF and FAULT_SHORT are traversal_ctrl's (a pop one entry off, a pipeline one cycle
// short).
module traversal_threads #(
    parameter int E               = 7,
    parameter int M               = 16,
    parameter int LAT_ADD         = 3,
    parameter int LAT_DIV         = 8,
    parameter int LAT_CMP         = 1,
    parameter int P               = 4,
    parameter int THREADS         = 64,
    parameter int STACK           = 64,
    parameter int NODE_W          = 28,
    parameter bit SKIP_EMPTY      = 1'b1,
    parameter bit EXIT_ONLY       = 1'b1,
    parameter bit FAULT_PRIO_SWAP = 1'b0,
    parameter bit FAULT_POP_OFF   = 1'b0,
    parameter bit FAULT_SHORT     = 1'b0,
    localparam int W              = E + M + 1,
    localparam int TW             = THREADS > 1 ? $clog2(THREADS) : 1,
    localparam int SW             = $clog2(STACK + 1)
) (
    input  logic              clk,
    input  logic              rst,
    input  logic [   3*W-1:0] scene_lo,
    input  logic [   3*W-1:0] scene_hi,
    input  logic [NODE_W-1:0] top_root,
    // Path payloads in the cycle the thread is pushed (traversal_ctrl's ports): the level start
    // with its rays on b (port 0) and RGS -> traversal (port 1); the hit update as the thread
    // leaves the intersection unit.
    input  logic [1:0]                  ld_valid,
    input  logic [1:0][TW-1:0]          ld_thread,
    input  logic [1:0]                  ld_bottom,
    input  logic [1:0]                  ld_shadow,
    input  logic [1:0][P-1:0]           ld_mask,
    input  logic [1:0][3*W-1:0]         ld_lo,
    input  logic [1:0][3*W-1:0]         ld_hi,
    input  logic [1:0][NODE_W-1:0]      ld_root,
    input  logic [1:0][P-1:0][3*W-1:0]  ld_o,
    input  logic [1:0][P-1:0][3*W-1:0]  ld_d,
    input  logic [1:0][P-1:0][W-1:0]    ld_tbest,
    input  logic [1:0][P-1:0]           ld_lane_valid,
    input  logic [1:0][P-1:0]           ld_done,
    input  logic                        hu_valid,
    input  logic [TW-1:0]               hu_thread,
    input  logic [P-1:0][W-1:0]         hu_tbest,
    input  logic [P-1:0]                hu_done,
    // Input paths (a thread pushed this cycle).
    input  logic              f_valid,
    input  logic [    TW-1:0] f_thread,
    input  logic              l_valid,
    input  logic [    TW-1:0] l_thread,
    input  logic              r_valid,
    input  logic [    TW-1:0] r_thread,
    input  logic              b_valid,
    input  logic [    TW-1:0] b_thread,
    // The traversal cache (kd-nodes): request by node index, tagged with the thread.
    output logic              req_valid,
    output logic [NODE_W-1:0] req_item,
    output logic [    TW-1:0] req_thread,
    input  logic              req_ready,
    input  logic              resp_valid,
    input  logic [    TW-1:0] resp_thread,
    input  logic [      31:0] resp_w0,
    input  logic [      31:0] resp_w1,
    // Leaving threads (dest 0: the unit's own loop, taken back inside; 1: leaf to the list unit,
    // 2: the top level's list, 3: the RGS); port 2 carries pops that dropped stack entries. The
    // fields a destination does not carry are 0 (traversal_ctrl).
    output logic              out_valid,
    output logic [    TW-1:0] out_thread,
    output logic [       1:0] out_dest,
    output logic [NODE_W-1:0] out_node,
    output logic [      31:0] out_first,
    output logic [      31:0] out_end,
    output logic [     P-1:0] out_mask,
    output logic              out_level,
    output logic              out2_valid,
    output logic [    TW-1:0] out2_thread,
    output logic [       1:0] out2_dest,
    output logic [NODE_W-1:0] out2_node,
    output logic [     P-1:0] out2_mask,
    output logic              out2_level,
    // The issue slot, for tests: the thread issued this cycle.
    output logic              iss_valid,
    output logic [    TW-1:0] iss_thread,
    output logic              overflow,
    // A thread's stack size, for tests.
    input  logic [    TW-1:0] dbg_thread,
    output logic [    SW-1:0] dbg_size,
    // The parameters, as constants: a test pins them to the cycle model's table.
    output logic [      15:0] par_packet,
    output logic [      15:0] par_threads,
    output logic [      15:0] par_stack,
    output logic [      15:0] par_depth,
    output logic              par_skip_empty,
    output logic              par_exit_only
);
  assign par_packet = 16'(P);
  assign par_threads = 16'(THREADS);
  assign par_stack = 16'(STACK);
  assign par_depth = 16'(LAT_ADD + LAT_DIV + LAT_CMP);
  assign par_skip_empty = SKIP_EMPTY;
  assign par_exit_only = EXIT_ONLY;
  localparam int Depth = LAT_ADD + LAT_DIV + LAT_CMP;
  localparam int Inputs = 5;  // loop, f, list, RGS, b

  // ---- per-thread: what the accepted request is, the node words it fetched ------------------
  localparam logic [1:0] KNode = 2'd0, KClip = 2'd1, KPop = 2'd2;
  logic [1:0] kind_r[THREADS];
  logic pop_r[THREADS];  // arrived on f or list -> traversal: its request is a pop
  logic [31:0] w0_r[THREADS], w1_r[THREADS];

  // ---- the core ------------------------------------------------------------------------------
  logic acc_valid;
  logic [TW-1:0] acc_thread;
  logic rq_clip;
  logic [NODE_W-1:0] rq_node;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [2:0] rq_face;  // the clip face and mask: the lockstep monitor's, not the machinery's
  logic [P-1:0] rq_mask;
  /* verilator lint_on UNUSEDSIGNAL */
  logic c_busy, c_chain;
  logic c_out_valid, c_out2_valid;
  logic [TW-1:0] c_out_thread, c_out2_thread;
  logic [1:0] c_out_dest, c_out2_dest;
  logic ut_iss_valid;
  logic [TW-1:0] ut_iss_thread;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [W-1:0] dbg_tn, dbg_tf, dbg_ctn, dbg_ctf;
  logic dbg_level;
  /* verilator lint_on UNUSEDSIGNAL */

  traversal_ctrl #(
      .E(E), .M(M), .LAT_ADD(LAT_ADD), .LAT_DIV(LAT_DIV), .LAT_CMP(LAT_CMP), .P(P),
      .THREADS(THREADS), .STACK(STACK), .NODE_W(NODE_W), .SKIP_EMPTY(SKIP_EMPTY),
      .EXIT_ONLY(EXIT_ONLY), .FAULT_POP_OFF(FAULT_POP_OFF), .FAULT_SHORT(FAULT_SHORT)
  ) u_core (
      .clk, .rst, .scene_lo, .scene_hi, .top_root,
      .ld_valid, .ld_thread, .ld_bottom, .ld_shadow, .ld_mask, .ld_lo, .ld_hi, .ld_root, .ld_o,
      .ld_d, .ld_tbest, .ld_lane_valid, .ld_done, .hu_valid, .hu_thread, .hu_tbest, .hu_done,
      .rq_thread(acc_thread), .rq_clip, .rq_face, .rq_node, .rq_mask,
      .is_valid(ut_iss_valid && !c_busy), .is_thread(ut_iss_thread),
      .is_kind(kind_r[ut_iss_thread]), .is_w0(w0_r[ut_iss_thread]), .is_w1(w1_r[ut_iss_thread]),
      .is_busy(c_busy), .is_chain(c_chain),
      .out_valid(c_out_valid), .out_thread(c_out_thread), .out_dest(c_out_dest),
      .out_node, .out_first, .out_end, .out_mask, .out_level,
      .out2_valid(c_out2_valid), .out2_thread(c_out2_thread), .out2_dest(c_out2_dest),
      .out2_node, .out2_mask, .out2_level, .overflow,
      .dbg_thread, .dbg_lane('0), .dbg_tn, .dbg_tf, .dbg_ctn, .dbg_ctf, .dbg_size, .dbg_level
  );

  // ---- the thread machinery --------------------------------------------------------------------
  logic [Inputs-1:0] in_valid;
  logic [Inputs*TW-1:0] in_thread;  // path i's thread at [i*TW +: TW]
  localparam int PathF = FAULT_PRIO_SWAP ? 4 : 1, PathB = FAULT_PRIO_SWAP ? 1 : 4;
  always_comb begin
    // One loop path, as the model's: the two output ports never send to the same unit in one
    // cycle (traversal_ctrl holds the pop queue's head), so its threads queue in arrival order.
    in_valid[0] = (c_out_valid && c_out_dest == 2'd0) || (c_out2_valid && c_out2_dest == 2'd0);
    in_thread[0+:TW] = c_out_valid && c_out_dest == 2'd0 ? c_out_thread : c_out2_thread;
    in_valid[PathF] = f_valid;
    in_thread[PathF*TW+:TW] = f_thread;
    in_valid[2] = l_valid;
    in_thread[2*TW+:TW] = l_thread;
    in_valid[3] = r_valid;
    in_thread[3*TW+:TW] = r_thread;
    in_valid[PathB] = b_valid;
    in_thread[PathB*TW+:TW] = b_thread;
  end

  logic acc_node;
  assign acc_node = !rq_clip && !pop_r[acc_thread];
  /* verilator lint_off UNUSEDSIGNAL */
  logic ut_out_valid;
  logic [TW-1:0] ut_out_thread;
  logic ut_out_payload;
  logic [31:0] ut_req_item;
  /* verilator lint_on UNUSEDSIGNAL */
  unit_threads #(
      .THREADS(THREADS), .INPUTS(Inputs), .DEPTH(Depth), .PW(1), .IW(32), .CW(1), .SW(1)
  ) u_threads (
      .clk, .rst, .in_valid, .in_thread, .acc_valid, .acc_thread,
      .acc_first(32'(rq_node)), .acc_count(acc_node),
      .req_valid, .req_item(ut_req_item), .req_thread, .req_ready, .resp_valid, .resp_thread,
      .iss_valid(ut_iss_valid), .iss_thread(ut_iss_thread), .iss_steps(1'b1),
      .iss_chain(c_chain), .iss_payload(1'b0),
      .out_valid(ut_out_valid), .out_thread(ut_out_thread), .out_payload(ut_out_payload),
      .out_ready(1'b1)
  );
  assign req_item = ut_req_item[NODE_W-1:0];
  assign iss_valid = ut_iss_valid;
  assign iss_thread = ut_iss_thread;

  assign out_valid = c_out_valid;
  assign out_thread = c_out_thread;
  assign out_dest = c_out_dest;
  assign out2_valid = c_out2_valid;
  assign out2_thread = c_out2_thread;
  assign out2_dest = c_out2_dest;

  always_ff @(posedge clk) begin
    if (rst) begin
      for (int t = 0; t < THREADS; t++) pop_r[t] <= 1'b0;
    end else begin
      if (f_valid) pop_r[f_thread] <= 1'b1;
      if (l_valid) pop_r[l_thread] <= 1'b1;
      if (acc_valid) begin
        // A thread on f or list -> traversal pops, whatever it last asked of this unit.
        kind_r[acc_thread] <= pop_r[acc_thread] ? KPop : (rq_clip ? KClip : KNode);
        pop_r[acc_thread] <= 1'b0;
      end
      if (resp_valid) begin
        w0_r[resp_thread] <= resp_w0;
        w1_r[resp_thread] <= resp_w1;
      end
    end
  end
endmodule
