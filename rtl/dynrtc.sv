// The whole DynRTC of one DynRTP (paper section 3.1, Figure 2): the four units around the three
// per-type caches, with the simple routing to the memory controller's cache port. Everything
// between the units is wired here (the paths of docs/hw-interface.md "The paths between units"):
//   b  transformation (dest 0)  -> traversal, load port 0: the level's rays, box and root
//   c  traversal (dest 1, 2)    -> list, path 2: a leaf's list starts, or the top level's resumes
//   d  list (kind 0)            -> transformation: the entry, its rays, the list's rays, last
//   e  transformation (dest 1)  -> intersection: the unit-triangle rays and the candidate's ids
//   f  intersection (dest 1)    -> traversal: a pop; every output is also the hit update
//      intersection (dest 0)    -> list, path 1: the bottom-level list resumes
//      list (kind 1)            -> list, path 0: the unit's own loop (a mailbox skip)
//      list (kind 2)            -> traversal: a pop
// What stays outside, in the cycle model, meets it at the DynRTC's boundary: the RGS (path a into
// the transformation unit with its side bands to the list and intersection units, RGS ->
// traversal on load port 1, and what leaves for it: path g and generated shadow rays) and the
// memory controller (the routing's port). The units' ports are also brought out (the mon_*-like
// outputs named by unit: tv_ traversal, ls_ list, tf_ transformation, is_ intersection, c_ the
// caches, k = 0 node, 1 list, 2 row) so that a testbench sees every internal port, as the
// boundary record (units/boundary.h) names them.
// A top-level entry is an object and a bottom-level one a triangle; the intersection unit works
// on bottom-level lists only, so its resume arrives at level 1.
// Several DynRTCs share one controller port through a chip-level routing (ext_route: the caches'
// line-request and fill queues are then the x_* ports, and the DynRTC's own routing is idle).
module dynrtc #(
    parameter int THREADS = 64,
    parameter int P       = 4,
    parameter int STACK   = 64,
    parameter int MB      = 8,
    parameter int TMB     = 8,
    parameter int LAT_ADD = 3,
    parameter int LAT_MUL = 3,
    parameter int LAT_DIV = 8,
    parameter int LAT_CMP = 1,
    parameter int ITEMS   = 512,  // each cache's arrays (the run's sizes are cfg inputs)
    parameter int WAYS    = 4,
    parameter int HIT_LAT = 2,
    parameter int MISSES  = 8,
    parameter int TARGETS = 16,
    parameter int REQ_CAP = 4,
    parameter int MEM_CAP = 2,
    parameter int RESP_CAP = 4,  // the controller port's response channel
    parameter int NODE_W  = 28,
    localparam int W      = 24,
    localparam int TW     = THREADS > 1 ? $clog2(THREADS) : 1,
    localparam int LW     = 12,  // cache label tag bits
    localparam int MW     = MISSES > 1 ? $clog2(MISSES) : 1,
    localparam int DW     = 4 * 32
) (
    input  logic                  clk,
    input  logic                  rst,
    // Frame registers and the caches' configuration (lines and ways as log2, item words, base;
    // node cache at [0], list cache [1], row cache [2]; fields of k at [k*5 +: 5], [k*3 +: 3],
    // [k*32 +: 32]); the routing's client ids ([k*16 +: 16]).
    input  logic [3*W-1:0]        scene_lo,
    input  logic [3*W-1:0]        scene_hi,
    input  logic [NODE_W-1:0]     top_root,
    input  logic [31:0]           instance_row_base,
    input  logic [14:0]           cfg_lines_log2,
    input  logic [14:0]           cfg_ways_log2,
    input  logic [8:0]            cfg_words,
    input  logic [95:0]           cfg_base,
    input  logic [47:0]           cfg_id,
    // Path a (the RGS): a packet to generate (transformation_threads' ports) ...
    input  logic                  a_valid,
    input  logic [TW-1:0]         a_thread,
    input  logic                  a_shadow,
    input  logic                  a_shared,
    input  logic [P-1:0]          a_valid_lanes,
    input  logic [P*288-1:0]      a_t,
    input  logic [P*72-1:0]       a_ro,
    input  logic [P*72-1:0]       a_rd,
    // ... and its side bands: the list unit's mailbox clear, the intersection unit's hit reset.
    input  logic [1:0]            clr_valid,
    input  logic [2*TW-1:0]       clr_thread,
    input  logic [1:0]            st_valid,
    input  logic [2*TW-1:0]       st_thread,
    input  logic [1:0]            st_shadow,
    // RGS -> traversal: a shadow packet's level start on load port 1 (traversal_threads' ld_*
    // ports; port 0 is path b, wired inside: its bits here are not read).
    input  logic                        r_valid,
    input  logic [TW-1:0]               r_thread,
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
    // The memory controller's cache port: its request channel full (the routing waits), a
    // response it pushes into the port's response channel.
    input  logic                  port_blocked,
    input  logic                  rsp_valid,
    input  logic [15:0]           rsp_client,
    input  logic [MW-1:0]         rsp_tag,
    input  logic [DW-1:0]         rsp_words,
    // A chip-level routing instead of the DynRTC's own (ext_route: several DynRTCs share one
    // controller port, as the model's pipelines do): the caches' memory sides, k = 0 node, 1 list,
    // 2 row; the fill's tag and words are the routing's shared bus.
    input  logic                  ext_route,
    output logic [2:0]            x_mq_valid,
    output logic [2:0]            x_fill_ready,
    input  logic [2:0]            x_mem_take,
    input  logic [2:0]            x_fill_valid,
    input  logic [MW-1:0]         x_fill_tag,
    input  logic [DW-1:0]         x_fill_words,
    // ---- the units' ports, observed ---------------------------------------------------------
    output logic                  tv_req,
    output logic [NODE_W-1:0]     tv_req_item,
    output logic [TW-1:0]         tv_req_thread,
    output logic                  tv_out_valid,
    output logic [TW-1:0]         tv_out_thread,
    output logic [1:0]            tv_out_dest,
    output logic [NODE_W-1:0]     tv_out_node,
    output logic [31:0]           tv_out_first,
    output logic [31:0]           tv_out_end,
    output logic [P-1:0]          tv_out_mask,
    output logic                  tv_out_level,
    output logic                  tv_out2_valid,
    output logic [TW-1:0]         tv_out2_thread,
    output logic [1:0]            tv_out2_dest,
    output logic [NODE_W-1:0]     tv_out2_node,
    output logic [P-1:0]          tv_out2_mask,
    output logic                  tv_out2_level,
    output logic                  ls_req,
    output logic [31:0]           ls_req_item,
    output logic [TW-1:0]         ls_req_thread,
    output logic                  ls_out_valid,
    output logic [TW-1:0]         ls_out_thread,
    output logic [1:0]            ls_out_kind,
    output logic                  ls_out_level,
    output logic [31:0]           ls_out_next,
    output logic [31:0]           ls_out_entry,
    output logic [P-1:0]          ls_out_mask,
    output logic [P-1:0]          ls_out_list,
    output logic                  ls_out_last,
    output logic                  tf_req,
    output logic [31:0]           tf_req_item,
    output logic [TW-1:0]         tf_req_thread,
    output logic                  tf_out_valid,
    output logic [TW-1:0]         tf_out_thread,
    output logic [1:0]            tf_out_dest,
    output logic                  tf_out_level,
    output logic                  tf_out_shared,
    output logic [P-1:0]          tf_out_mask,
    output logic [31:0]           tf_out_root,
    output logic [P*72-1:0]       tf_out_o,
    output logic [P*72-1:0]       tf_out_d,
    output logic [71:0]           tf_out_lo,
    output logic [71:0]           tf_out_hi,
    output logic [P-1:0]          tf_out_list,
    output logic                  tf_out_last,
    output logic [31:0]           tf_out_instance,
    output logic [31:0]           tf_out_triangle,
    output logic                  tf_out_shadow,
    output logic                  is_out_valid,
    output logic [TW-1:0]         is_out_thread,
    output logic                  is_out_dest,
    output logic [P-1:0]          is_out_mask,
    output logic [P-1:0]          is_out_done,
    output logic [P*24-1:0]       is_out_t,
    output logic [P*24-1:0]       is_out_u,
    output logic [P*24-1:0]       is_out_v,
    output logic [P*24-1:0]       is_out_c,
    output logic [P*32-1:0]       is_out_instance,
    output logic [P*32-1:0]       is_out_triangle,
    // The caches, k = 0 node, 1 list, 2 row: lookups, replies, line requests, and what the
    // routing did to each (took its line request, pushed a fill).
    output logic [2:0]            c_acc_valid,
    output logic [3*32-1:0]       c_acc_index,
    output logic [3*3-1:0]        c_acc_requester,
    output logic [3*LW-1:0]       c_acc_tag,
    output logic [3*2-1:0]        c_acc_kind,
    output logic [3*MW-1:0]       c_acc_mshr,
    output logic [2:0]            c_resp_valid,
    output logic [3*32-1:0]       c_resp_index,
    output logic [3*3-1:0]        c_resp_requester,
    output logic [3*LW-1:0]       c_resp_tag,
    output logic [3*DW-1:0]       c_resp_words,
    output logic [2:0]            c_mreq_valid,
    output logic [3*MW-1:0]       c_mreq_tag,
    output logic [3*3-1:0]        c_mreq_bank,
    output logic [3*32-1:0]       c_mreq_offset,
    output logic [3*3-1:0]        c_mreq_words,
    output logic [2:0]            c_mem_take,
    output logic [2:0]            c_fill_valid,
    output logic [MW-1:0]         c_fill_tag,
    output logic [DW-1:0]         c_fill_words,
    // The wiring's own checks: two threads for one list path in a cycle; the routing's response
    // channel overflowed or a response named no client of ours.
    output logic                  conflict,
    output logic                  routing_error
);
  localparam logic [W-1:0] kInf = {1'b0, {7{1'b1}}, 16'd0};  // fp24 +inf

  // ---- the caches' unit-side ports ------------------------------------------------------------
  logic [2:0]        c_req_valid, c_req_ready;
  logic [3*32-1:0]   c_req_index;
  logic [3*3-1:0]    c_req_requester;
  logic [3*LW-1:0]   c_req_tag;
  logic [2:0]        c_mq_valid, c_fill_ready;
  logic [2:0]        r_mem_take, r_fill_valid;
  logic [MW-1:0]     r_fill_tag;
  logic [DW-1:0]     r_fill_words;
  assign x_mq_valid = c_mq_valid;
  assign x_fill_ready = c_fill_ready;
  assign c_mem_take = ext_route ? x_mem_take : r_mem_take;
  assign c_fill_valid = ext_route ? x_fill_valid : r_fill_valid;
  assign c_fill_tag = ext_route ? x_fill_tag : r_fill_tag;
  assign c_fill_words = ext_route ? x_fill_words : r_fill_words;

  // ---- traversal ------------------------------------------------------------------------------
  logic tv_req_valid;
  logic [1:0] tv_ld_valid;
  logic [1:0][TW-1:0] tv_ld_thread;
  logic [1:0] tv_ld_bottom, tv_ld_shadow;
  logic [1:0][P-1:0] tv_ld_mask, tv_ld_lane_valid, tv_ld_done;
  logic [1:0][3*W-1:0] tv_ld_lo, tv_ld_hi;
  logic [1:0][NODE_W-1:0] tv_ld_root;
  logic [1:0][P-1:0][3*W-1:0] tv_ld_o, tv_ld_d;
  logic [1:0][P-1:0][W-1:0] tv_ld_tbest;
  logic b_valid;
  assign b_valid = tf_out_valid && tf_out_dest == 2'd0;
  always_comb begin
    tv_ld_valid = {ld_valid[1], b_valid};
    tv_ld_thread = {ld_thread[1], tf_out_thread};
    tv_ld_bottom = {ld_bottom[1], tf_out_level};
    tv_ld_shadow = {ld_shadow[1], tf_out_shadow};
    tv_ld_mask = {ld_mask[1], tf_out_mask};
    tv_ld_lo = {ld_lo[1], tf_out_lo};
    tv_ld_hi = {ld_hi[1], tf_out_hi};
    tv_ld_root = {ld_root[1], NODE_W'(tf_out_root)};
    tv_ld_o = {ld_o[1], tf_out_o};
    tv_ld_d = {ld_d[1], tf_out_d};
    // A top level's start on b: its rays' closest hits are +inf (only shadow rays, which come
    // from the RGS, start at 1 - 1/512), no lane is done; a bottom level's reads the unit's copy.
    tv_ld_tbest = {ld_tbest[1], {P{kInf}}};
    tv_ld_lane_valid = {ld_lane_valid[1], tf_out_mask};
    tv_ld_done = {ld_done[1], {P{1'b0}}};
  end
  /* verilator lint_off UNUSEDSIGNAL */
  logic unused_ld;
  assign unused_ld = ^{ld_valid[0], ld_thread[0], ld_bottom[0], ld_shadow[0], ld_mask[0],
                       ld_lo[0], ld_hi[0], ld_root[0], ld_o[0], ld_d[0], ld_tbest[0],
                       ld_lane_valid[0], ld_done[0], tf_out_root[31:NODE_W]};
  logic tv_iss_valid, tv_overflow;
  logic [TW-1:0] tv_iss_thread;
  logic [$clog2(STACK + 1)-1:0] tv_dbg_size;
  logic [15:0] tv_par_packet, tv_par_threads, tv_par_stack, tv_par_depth;
  logic tv_par_skip_empty, tv_par_exit_only;
  /* verilator lint_on UNUSEDSIGNAL */
  traversal_threads #(
      .LAT_ADD(LAT_ADD), .LAT_DIV(LAT_DIV), .LAT_CMP(LAT_CMP), .P(P), .THREADS(THREADS),
      .STACK(STACK), .NODE_W(NODE_W)
  ) traversal (
      .clk, .rst, .scene_lo, .scene_hi, .top_root,
      .ld_valid(tv_ld_valid), .ld_thread(tv_ld_thread), .ld_bottom(tv_ld_bottom),
      .ld_shadow(tv_ld_shadow), .ld_mask(tv_ld_mask), .ld_lo(tv_ld_lo), .ld_hi(tv_ld_hi),
      .ld_root(tv_ld_root), .ld_o(tv_ld_o), .ld_d(tv_ld_d), .ld_tbest(tv_ld_tbest),
      .ld_lane_valid(tv_ld_lane_valid), .ld_done(tv_ld_done),
      .hu_valid(is_out_valid), .hu_thread(is_out_thread), .hu_tbest(is_out_t),
      .hu_done(is_out_done),
      .f_valid(is_out_valid && is_out_dest), .f_thread(is_out_thread),
      .l_valid(ls_out_valid && ls_out_kind == 2'd2), .l_thread(ls_out_thread),
      .r_valid, .r_thread, .b_valid, .b_thread(tf_out_thread),
      .req_valid(tv_req_valid), .req_item(tv_req_item), .req_thread(tv_req_thread),
      .req_ready(c_req_ready[0]), .resp_valid(c_resp_valid[0]),
      .resp_thread(TW'(c_resp_tag[0+:LW])), .resp_w0(c_resp_words[0+:32]),
      .resp_w1(c_resp_words[32+:32]),
      .out_valid(tv_out_valid), .out_thread(tv_out_thread), .out_dest(tv_out_dest),
      .out_node(tv_out_node), .out_first(tv_out_first), .out_end(tv_out_end),
      .out_mask(tv_out_mask), .out_level(tv_out_level),
      .out2_valid(tv_out2_valid), .out2_thread(tv_out2_thread), .out2_dest(tv_out2_dest),
      .out2_node(tv_out2_node), .out2_mask(tv_out2_mask), .out2_level(tv_out2_level),
      .iss_valid(tv_iss_valid), .iss_thread(tv_iss_thread), .overflow(tv_overflow),
      .dbg_thread('0), .dbg_size(tv_dbg_size),
      .par_packet(tv_par_packet), .par_threads(tv_par_threads), .par_stack(tv_par_stack),
      .par_depth(tv_par_depth), .par_skip_empty(tv_par_skip_empty),
      .par_exit_only(tv_par_exit_only));
  assign tv_req = tv_req_valid && c_req_ready[0];

  // ---- list -----------------------------------------------------------------------------------
  // Path 2 (from the traversal unit): a leaf's list (dest 1) or the top level's list after an
  // object (dest 2), from either output port.
  logic t1, t2;
  assign t1 = tv_out_valid && (tv_out_dest == 2'd1 || tv_out_dest == 2'd2);
  assign t2 = tv_out2_valid && (tv_out2_dest == 2'd1 || tv_out2_dest == 2'd2);
  logic [TW-1:0] c_thread;
  logic c_start;
  logic [P-1:0] c_mask;
  // The rays of a thread that no any-hit ended (the hit updates' done, cleared when a packet
  // starts): the top level's list resumes after an object with those of its rays still alive
  // (ListStep::return_to_list drops the done ones).
  logic [P-1:0] alive[THREADS];
  always_ff @(posedge clk) begin
    if (is_out_valid) alive[is_out_thread] <= ~is_out_done;
    for (int k = 0; k < 2; k++)
      if (st_valid[k]) alive[st_thread[k*TW+:TW]] <= '1;
  end
  always_comb begin
    c_thread = t1 ? tv_out_thread : tv_out2_thread;
    c_start = t1 ? tv_out_dest == 2'd1 : tv_out2_dest == 2'd1;
    c_mask = c_start ? (t1 ? tv_out_mask : tv_out2_mask) : alive[c_thread];
  end
  logic ls_req_valid;
  list_unit #(.THREADS(THREADS), .P(P), .MB(MB), .TMB(TMB), .DEPTH(LAT_CMP)) list (
      .clk, .rst,
      .in_valid({t1 || t2, is_out_valid && !is_out_dest, ls_out_valid && ls_out_kind == 2'd1}),
      .in_thread({c_thread, is_out_thread, ls_out_thread}),
      .in_start({c_start, 1'b0, 1'b0}),
      // A leaf's list at its level; the top level's list after an object; the intersection
      // unit's resume at the bottom level; the loop at the entry's level.
      .in_level({c_start && (t1 ? tv_out_level : tv_out2_level), 1'b1, ls_out_level}),
      .in_next({t1 ? tv_out_first : 32'd0, 32'd0, 32'd0}),
      .in_end({t1 ? tv_out_end : 32'd0, 32'd0, 32'd0}),
      .in_mask({c_mask, is_out_mask, ls_out_mask}),
      .clr_valid, .clr_thread,
      .req_valid(ls_req_valid), .req_item(ls_req_item), .req_thread(ls_req_thread),
      .req_ready(c_req_ready[1]), .resp_valid(c_resp_valid[1]),
      .resp_thread(TW'(c_resp_tag[LW+:LW])), .resp_word(c_resp_words[DW+:32]),
      .out_valid(ls_out_valid), .out_thread(ls_out_thread), .out_kind(ls_out_kind),
      .out_level(ls_out_level), .out_next(ls_out_next), .out_entry(ls_out_entry),
      .out_mask(ls_out_mask), .out_list(ls_out_list), .out_last(ls_out_last));
  assign ls_req = ls_req_valid && c_req_ready[1];
  // A leaf's list carries first and end on port 1 only (port 2 carries pops, whose leaf-less
  // destinations have none); two threads for path 2 in one cycle have no path to take them.
  assign conflict = t1 && t2;

  // ---- transformation -------------------------------------------------------------------------
  logic tf_req_valid;
  transformation_threads #(
      .THREADS(THREADS), .P(P), .LAT_ADD(LAT_ADD), .LAT_MUL(LAT_MUL)
  ) transformation (
      .clk, .rst, .instance_row_base,
      .d_valid(ls_out_valid && ls_out_kind == 2'd0), .d_thread(ls_out_thread),
      .d_kind(ls_out_level), .d_entry(ls_out_entry), .d_mask(ls_out_mask),
      .d_list(ls_out_list), .d_last(ls_out_last),
      .a_valid, .a_thread, .a_shadow, .a_shared, .a_valid_lanes, .a_t, .a_ro, .a_rd,
      .req_valid(tf_req_valid), .req_item(tf_req_item), .req_thread(tf_req_thread),
      .req_ready(c_req_ready[2]), .resp_valid(c_resp_valid[2]),
      .resp_thread(TW'(c_resp_tag[2*LW+:LW])), .resp_item(c_resp_index[64+:32]),
      .resp_words(c_resp_words[2*DW+:96]),
      .out_valid(tf_out_valid), .out_thread(tf_out_thread), .out_dest(tf_out_dest),
      .out_level(tf_out_level), .out_shared(tf_out_shared), .out_mask(tf_out_mask),
      .out_root(tf_out_root), .out_o(tf_out_o), .out_d(tf_out_d), .out_lo(tf_out_lo),
      .out_hi(tf_out_hi), .out_list(tf_out_list), .out_last(tf_out_last),
      .out_instance(tf_out_instance), .out_triangle(tf_out_triangle),
      .out_shadow(tf_out_shadow));
  assign tf_req = tf_req_valid && c_req_ready[2];

  // ---- intersection ---------------------------------------------------------------------------
  intersection_threads #(
      .THREADS(THREADS), .P(P), .LAT_ADD(LAT_ADD), .LAT_MUL(LAT_MUL), .LAT_DIV(LAT_DIV),
      .LAT_CMP(LAT_CMP)
  ) intersection (
      .clk, .rst,
      .in_valid(tf_out_valid && tf_out_dest == 2'd1), .in_thread(tf_out_thread),
      .in_mask(tf_out_mask), .in_list(tf_out_list), .in_last(tf_out_last),
      .in_instance(tf_out_instance), .in_triangle(tf_out_triangle), .in_o(tf_out_o),
      .in_d(tf_out_d), .st_valid, .st_thread, .st_shadow,
      .out_valid(is_out_valid), .out_thread(is_out_thread), .out_dest(is_out_dest),
      .out_mask(is_out_mask), .out_done(is_out_done), .out_t(is_out_t), .out_u(is_out_u),
      .out_v(is_out_v), .out_c(is_out_c), .out_instance(is_out_instance),
      .out_triangle(is_out_triangle));

  // ---- the three caches -----------------------------------------------------------------------
  // Requests labelled with the requesting unit (units/program_types.h UnitId: the
  // transformation unit 1, traversal 2, list 3) and the thread.
  always_comb begin
    c_req_valid = {tf_req_valid, ls_req_valid, tv_req_valid};
    c_req_index = {tf_req_item, ls_req_item, 32'(tv_req_item)};
    c_req_requester = {3'd1, 3'd3, 3'd2};
    c_req_tag = {LW'(tf_req_thread), LW'(ls_req_thread), LW'(tv_req_thread)};
  end
  logic [3*MW-1:0] c_mq_tag_unused;
  logic [3*3-1:0] c_mq_bank_unused;
  logic [3*32-1:0] c_mq_offset_unused;
  for (genvar k = 0; k < 3; k++) begin : caches
    cache #(
        .ITEMS(ITEMS), .WAYS(WAYS), .WORDS(4), .HIT_LAT(HIT_LAT), .MISSES(MISSES),
        .TARGETS(TARGETS), .REQ_CAP(REQ_CAP), .MEM_CAP(MEM_CAP), .RW(3), .TW(LW)
    ) c (
        .clk, .rst, .cfg_lines_log2(cfg_lines_log2[k*5+:5]), .cfg_ways_log2(cfg_ways_log2[k*5+:5]),
        .cfg_words(cfg_words[k*3+:3]), .cfg_base(cfg_base[k*32+:32]),
        .req_valid(c_req_valid[k]), .req_index(c_req_index[k*32+:32]),
        .req_requester(c_req_requester[k*3+:3]), .req_tag(c_req_tag[k*LW+:LW]),
        .req_ready(c_req_ready[k]),
        .acc_valid(c_acc_valid[k]), .acc_index(c_acc_index[k*32+:32]),
        .acc_requester(c_acc_requester[k*3+:3]), .acc_tag(c_acc_tag[k*LW+:LW]),
        .acc_kind(c_acc_kind[k*2+:2]), .acc_mshr(c_acc_mshr[k*MW+:MW]),
        .resp_valid(c_resp_valid[k]), .resp_index(c_resp_index[k*32+:32]),
        .resp_requester(c_resp_requester[k*3+:3]), .resp_tag(c_resp_tag[k*LW+:LW]),
        .resp_words(c_resp_words[k*DW+:DW]),
        .mreq_valid(c_mreq_valid[k]), .mreq_tag(c_mreq_tag[k*MW+:MW]),
        .mreq_bank(c_mreq_bank[k*3+:3]), .mreq_offset(c_mreq_offset[k*32+:32]),
        .mreq_words(c_mreq_words[k*3+:3]),
        .mq_valid(c_mq_valid[k]), .mq_tag(c_mq_tag_unused[k*MW+:MW]),
        .mq_bank(c_mq_bank_unused[k*3+:3]), .mq_offset(c_mq_offset_unused[k*32+:32]),
        .mem_take(c_mem_take[k]),
        .fill_valid(c_fill_valid[k]), .fill_tag(c_fill_tag), .fill_words(c_fill_words),
        .fill_ready(c_fill_ready[k]));
  end
  /* verilator lint_off UNUSEDSIGNAL */
  // The line request's fields go to the controller with the routing's label; the controller is
  // the model's, which has them from the model's own routing (they are compared at mreq).
  logic unused_mq;
  assign unused_mq = ^{c_mq_tag_unused, c_mq_bank_unused, c_mq_offset_unused};
  /* verilator lint_on UNUSEDSIGNAL */

  // ---- the simple routing ---------------------------------------------------------------------
  logic r_fwd_valid, r_overflow, r_unknown;
  logic [1:0] r_fwd_client;
  routing #(.CLIENTS(3), .RESP_CAP(RESP_CAP), .TAG_W(MW), .WORDS(4)) route (
      .clk, .rst, .cfg_id, .mq_valid(ext_route ? 3'b000 : c_mq_valid), .mem_take(r_mem_take),
      .port_blocked, .fwd_valid(r_fwd_valid), .fwd_client(r_fwd_client),
      .rsp_valid(rsp_valid && !ext_route), .rsp_client, .rsp_tag, .rsp_words,
      .fill_ready(c_fill_ready), .fill_valid(r_fill_valid), .fill_tag(r_fill_tag),
      .fill_words(r_fill_words), .overflow(r_overflow), .unknown_client(r_unknown));
  assign routing_error = r_overflow || r_unknown;
  /* verilator lint_off UNUSEDSIGNAL */
  logic unused_fwd;
  assign unused_fwd = ^{r_fwd_valid, r_fwd_client};
  /* verilator lint_on UNUSEDSIGNAL */
endmodule
