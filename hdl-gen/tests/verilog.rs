//! The typed Verilog writer (`hdl_gen::verilog`): what it renders, checked on small modules.

use hdl_gen::verilog::*;

#[test]
fn renders_a_small_module() {
    let m = Module {
        name: "t".into(),
        header: vec!["A test.".into()],
        params: vec![],
        ports: vec![Port::input("clk", 1, "", "clock"), Port::input("a", 4, "UQ4.0", "").signed(), Port::output("y", 4, "", "").reg()],
        body: vec![Item::Always(vec![Stmt::If(
            "a[3]".into(),
            vec![set("y", "a")],
            vec![Stmt::If("a[2]".into(), vec![set("y", "4'd1")], vec![set("y", "4'd0")])],
        )])],
    };
    let text = m.render();
    assert!(text.contains("input  wire signed [3:0] a,"), "{text}");
    assert!(text.contains("output reg  [3:0] y "), "{text}");
    assert!(text.contains("end else if (a[2]) begin\n"), "{text}");
}

#[test]
fn attributes_precede_their_port() {
    let m = Module {
        name: "t".into(),
        header: vec![],
        params: vec![],
        ports: vec![Port::input("clk", 1, "", "").attr("A = \"x\"").attr("B = \"y\""), Port::output("y", 1, "", "")],
        body: vec![assign("y", "clk")],
    };
    let text = m.render();
    assert!(text.contains("(\n  (* A = \"x\" *)\n  (* B = \"y\" *)\n  input  wire clk,"), "{text}");
    assert!(text.contains("clk, // \n  output wire y "), "{text}");
}

#[test]
fn gathers_rows_of_eight_most_significant_first() {
    let render = |n: usize| {
        let m = Module {
            name: "t".into(),
            header: vec![],
            params: vec![],
            ports: vec![],
            body: vec![gather("b", (0..n).map(|k| format!("l{k}")).collect())],
        };
        m.render()
    };
    assert!(render(3).contains("  always @(*) begin\n    b = {l2, l1, l0};\n  end\n"), "{}", render(3));
    let two = render(10);
    assert!(two.contains("    b = {\n      {l9, l8},\n      {l7, l6, l5, l4, l3, l2, l1, l0}\n    };\n  end\n"), "{two}");
}

#[test]
fn parameterised_widths_and_loops() {
    let m = Module {
        name: "t".into(),
        header: vec![],
        params: vec![Param { name: "W".into(), value: "4".into(), doc: "bits".into() }],
        ports: vec![Port::input("a", 4, "", "").param_width("W"), Port::output("y", 4, "", "").param_width("W").reg()],
        body: vec![
            sized(Kind::Localparam, "ONE", "W", Some("1".into())),
            Item::Integer("j".into()),
            Item::Comb(vec![
                Stmt::Blocking("y".into(), "a".into()),
                Stmt::For { var: "j".into(), count: "2".into(), body: vec![Stmt::Blocking("y".into(), "y + ONE".into())] },
            ]),
        ],
    };
    let text = m.render();
    assert!(text.contains("input  wire [W-1:0] a,"), "{text}");
    assert!(text.contains("output reg  [W-1:0] y "), "{text}");
    assert!(text.contains("  localparam [W-1:0] ONE = 1;\n  integer j;\n"), "{text}");
    assert!(text.contains("    for (j = 0; j < 2; j = j + 1) begin\n      y = y + ONE;\n    end\n"), "{text}");
}

#[test]
fn extensions() {
    assert_eq!(sext("d", 4, 6), "{{2{d[3]}}, d}");
    assert_eq!(sext("d", 4, 4), "d");
    assert_eq!(zext("d", 4, 6), "{2'd0, d}");
}
