//! What the view shows of the arm at one instant, how it is taken from the virtual robot, and
//! how it travels to the page (JSON text, one object per WebSocket message).

use std::fmt::Write as _;

use firmware_atom::cartesian::{self, Cartesian};
use firmware_atom::collision::Kind;
use firmware_basic::teach::{Activity, SAMPLE_PERIOD_US, TeachStatus};
use kinematics_core::ArmGeometry;
use kinematics_core::geometry::DH_ALPHA_CENTIDEG;
use protocol_core::command::{EndType, Pose, ReferenceFrame};
use protocol_core::dialect::Dialect;
use protocol_core::units::Centideg;

use crate::host::realtime::Lateness;
use crate::sim::VirtualRobot;

/// The arm at one instant, as the view draws and reads it out. Small and `Copy`, so the
/// simulation loop can hand it over without allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Snapshot {
    /// Virtual time since the robot started, microseconds.
    pub time_us: u64,
    /// Joint angles 1..6 where the servos' shafts really are ([`VirtualRobot::measured_angles`]).
    pub angles: [Centideg; 6],
    /// The end pose at those angles as `get_coords` reports it: flange or tool tip, base or
    /// world frame, per the frames the host selected.
    pub coords: Pose,
    /// Which point `coords` is: the flange or the tool tip.
    pub end: EndType,
    /// Which frame `coords` is in: the robot base or the world.
    pub reference: ReferenceFrame,
    /// The tool pose in the flange frame, when one is set (`set_tool_reference`, non-zero).
    pub tool: Option<Pose>,
    /// Gripper opening, 0 (closed) ..= 100 (open).
    pub gripper_percent: u8,
    /// The colour of the Atom's LEDs (red, green, blue).
    pub led_rgb: (u8, u8, u8),
    /// Whether the arm is powered on.
    pub powered: bool,
    /// Whether the Atom is running a motion.
    pub moving: bool,
    /// The dialect the Basic's clients speak; `None` without a Basic (the Atom's own port).
    pub dialect: Option<Dialect>,
    /// The collision the Atom detected and the host has not cleared yet.
    pub collision: Option<CollisionMark>,
    /// How late the simulation has run behind the wall clock because the machine could not
    /// keep up (zero in virtual-time runs).
    pub late: Lateness,
    /// What the Basic's teach-and-play program is doing, when it runs one
    /// ([`VirtualRobot::teach_status`]).
    pub teach: Option<TeachStatus>,
}

/// A collision as the view marks it: which joint, what error, when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CollisionMark {
    /// The joint that pressed, 1..=6.
    pub joint: u8,
    /// What the arm was doing; it chooses the error code 0x07 reports (16..=18).
    pub kind: Kind,
    /// When it was detected, virtual time in microseconds.
    pub time_us: u64,
}

impl Snapshot {
    /// The arm of `robot` now.
    ///
    /// The joint angles are the shafts' real positions, not the Atom's present angles: the view
    /// is a camera on the arm, so it shows where the arm is even when the firmware's idea of it
    /// is stale or wrong (a servo that stopped answering, a joint moved by hand); what the Atom
    /// believes is what `get_angles` already tells. The gripper opening is the Atom's reading of
    /// servo 7 (one refresh round old, about 4 ms), because only the Atom knows the calibrated
    /// range it maps onto 0..100; the LED colour is what the Atom last set.
    pub fn of(robot: &VirtualRobot) -> Self {
        let atom = robot.atom();
        let angles = robot.measured_angles();
        let frames = atom.cartesian();
        Self {
            time_us: robot.now_us(),
            angles,
            coords: coords_at(frames, &angles),
            end: frames.end(),
            reference: frames.reference(),
            tool: (frames.tool() != Pose::default()).then_some(frames.tool()),
            gripper_percent: atom.gripper_value(),
            led_rgb: robot.atom_io().rgb,
            powered: atom.is_powered(),
            moving: atom.is_moving(),
            dialect: robot.basic().map(|basic| basic.status().dialect),
            collision: atom.collision().and_then(|latched| {
                let &(at_ns, logged) = robot.collisions().last()?;
                (logged == latched).then(|| CollisionMark {
                    joint: u8::try_from(latched.joint + 1).unwrap_or(u8::MAX),
                    kind: latched.kind,
                    time_us: at_ns / 1_000,
                })
            }),
            late: Lateness::default(),
            teach: robot.teach_status(),
        }
    }

    /// The same snapshot, saying the simulation has run `late`.
    pub fn ran_late(self, late: Lateness) -> Self {
        Self { late, ..self }
    }

    /// The snapshot as one JSON object, the message the page receives:
    ///
    /// ```json
    /// {"t_s":1.5,"angles_deg":[10,20,-30,15,-25,40],
    ///  "coords":[x_mm,y_mm,z_mm,rx_deg,ry_deg,rz_deg],"end":"flange","frame":"base",
    ///  "tool":null,"gripper":50,"led":[255,0,0],"powered":true,"moving":false,
    ///  "collision":{"joint":2,"code":16,"during":"moving joints","t_s":3.25},
    ///  "late_ms":0,"late_stalls":0,"protocol":"pymycobot",
    ///  "basic_program":{"name":"teach","activity":"recording","points":81,"played":0,
    ///                   "plays":2,"error":null,"lines":["now       RECORDING",...]}}
    /// ```
    ///
    /// `basic_program`: the Basic's program and what it does ([`teach_json`]), or `null` when
    /// it runs none.
    ///
    /// `protocol`: the dialect the Basic's clients speak, or `null` without a Basic.
    ///
    /// `collision`: the collision not cleared yet ([`CollisionMark`]), or `null`.
    ///
    /// `late_ms` and `late_stalls`: how much wall time the simulation could not run, and in
    /// how many stalls ([`Lateness`]).
    pub fn to_json(&self) -> String {
        let mut out = String::with_capacity(256);
        let _ = write!(out, "{{\"t_s\":{}", self.time_us as f64 / 1e6);
        out.push_str(",\"angles_deg\":");
        push_list(&mut out, self.angles.iter().map(|a| hundredths(a.0)));
        out.push_str(",\"coords\":");
        push_pose(&mut out, &self.coords);
        let end = match self.end {
            EndType::Flange => "flange",
            EndType::Tool => "tool",
        };
        let frame = match self.reference {
            ReferenceFrame::Base => "base",
            ReferenceFrame::World => "world",
        };
        let _ = write!(out, ",\"end\":\"{end}\",\"frame\":\"{frame}\",\"tool\":");
        match &self.tool {
            Some(tool) => push_pose(&mut out, tool),
            None => out.push_str("null"),
        }
        let (r, g, b) = self.led_rgb;
        let _ = write!(
            out,
            ",\"gripper\":{},\"led\":[{r},{g},{b}],\"powered\":{},\"moving\":{},\"collision\":",
            self.gripper_percent, self.powered, self.moving,
        );
        match &self.collision {
            Some(c) => {
                let _ = write!(
                    out,
                    "{{\"joint\":{},\"code\":{},\"during\":\"{}\",\"t_s\":{}}}",
                    c.joint,
                    c.kind.code(),
                    c.kind.during(),
                    c.time_us as f64 / 1e6
                );
            }
            None => out.push_str("null"),
        }
        let _ = write!(
            out,
            ",\"late_ms\":{},\"late_stalls\":{},\"protocol\":",
            self.late.total_us as f64 / 1e3,
            self.late.stalls
        );
        match self.dialect {
            Some(d) => {
                let _ = write!(out, "\"{}\"", d.name());
            }
            None => out.push_str("null"),
        }
        out.push_str(",\"basic_program\":");
        match &self.teach {
            Some(teach) => push_teach(&mut out, teach),
            None => out.push_str("null"),
        }
        out.push('}');
        out
    }
}

/// The teach program's status as the view gets it: `{"name":"teach","activity":..,
/// "points":..,"played":..,"plays":..,"error":"text"|null,"lines":[..]}`; `activity` is
/// `idle`, `recording`, `approaching`, `playing`, `settling` or `stopping`, `lines` what the
/// board's screen says of it ([`teach_lines`]).
fn push_teach(out: &mut String, teach: &TeachStatus) {
    let activity = match teach.activity {
        Activity::Idle => "idle",
        Activity::Recording => "recording",
        Activity::Approaching => "approaching",
        Activity::Playing => "playing",
        Activity::Settling => "settling",
        Activity::Stopping => "stopping",
    };
    let _ = write!(
        out,
        "{{\"name\":\"teach\",\"activity\":\"{activity}\",\"points\":{},\"played\":{},\
         \"plays\":{},\"error\":",
        teach.points, teach.played, teach.plays
    );
    match &teach.error {
        Some(error) => push_string(out, &error.to_string()),
        None => out.push_str("null"),
    }
    out.push_str(",\"lines\":[");
    for (i, line) in teach_lines(teach).iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        push_string(out, line);
    }
    out.push_str("]}");
}

/// What the teach-and-play image's screen says of the program (its rows 4 to 6, in the
/// words of `render_teach` in `firmware-basic/src/bin/basic-teach/teach_text.rs`): what it
/// is doing, the record's length, the playbacks finished.
pub fn teach_lines(teach: &TeachStatus) -> [String; 3] {
    let now = match teach.activity {
        Activity::Idle if teach.points == 0 => "move by hand after A".to_string(),
        Activity::Idle => "ready".to_string(),
        Activity::Recording => "RECORDING".to_string(),
        Activity::Approaching => "to the first point".to_string(),
        Activity::Playing => format!("PLAYING {}/{}", teach.played, teach.points),
        Activity::Settling => "to the last point".to_string(),
        Activity::Stopping => "stopping".to_string(),
    };
    let tenths_s = u64::from(teach.points) * SAMPLE_PERIOD_US / 100_000;
    [
        format!("now       {now}"),
        format!(
            "record    {} points, {}.{} s",
            teach.points,
            tenths_s / 10,
            tenths_s % 10
        ),
        format!("played    {} times", teach.plays),
    ]
}

/// `text` as a JSON string, quotes, backslashes and control characters escaped.
fn push_string(out: &mut String, text: &str) {
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if u32::from(c) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

/// The end pose at `angles` as the Atom reports it (its frames, its rounding to the wire).
fn coords_at(frames: &Cartesian, angles: &[Centideg; 6]) -> Pose {
    let pose = frames.model().forward(&cartesian::joints(angles));
    cartesian::for_client(cartesian::from_kin(&pose))
}

/// The arm's DH table from kinematics-core, for the page to build and pose the arm with:
/// `{"d_mm":[..6],"a_mm":[..6],"alpha_deg":[..6],"theta_offset_deg":[..6]}` (standard DH,
/// A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i), theta_i = q_i + offset_i).
pub fn model_json(geometry: &ArmGeometry) -> String {
    let g = geometry;
    let micrometres = [g.d1_um, 0, 0, g.d4_um, g.d5_um, g.d6_um];
    let a_micrometres = [0, g.a2_um, g.a3_um, 0, 0, 0];
    let mut out = String::with_capacity(192);
    out.push_str("{\"d_mm\":");
    push_list(&mut out, micrometres.iter().map(|&um| f64::from(um) / 1e3));
    out.push_str(",\"a_mm\":");
    push_list(
        &mut out,
        a_micrometres.iter().map(|&um| f64::from(um) / 1e3),
    );
    out.push_str(",\"alpha_deg\":");
    push_list(
        &mut out,
        DH_ALPHA_CENTIDEG.iter().map(|&c| f64::from(c) / 1e2),
    );
    out.push_str(",\"theta_offset_deg\":");
    push_list(
        &mut out,
        g.theta_offset_centideg.iter().map(|&c| f64::from(c) / 1e2),
    );
    out.push('}');
    out
}

/// A value in hundredths (centidegrees) as a plain number.
fn hundredths(v: i16) -> f64 {
    f64::from(v) / 100.0
}

/// `[x_mm, y_mm, z_mm, rx_deg, ry_deg, rz_deg]`.
fn push_pose(out: &mut String, pose: &Pose) {
    let [x, y, z, rx, ry, rz] = pose.to_array();
    let tenths = |v: i16| f64::from(v) / 10.0;
    push_list(
        out,
        [
            tenths(x),
            tenths(y),
            tenths(z),
            hundredths(rx),
            hundredths(ry),
            hundredths(rz),
        ],
    );
}

/// `[a,b,...]`. Every value comes from an integer, so it is finite and prints as plain JSON.
fn push_list(out: &mut String, values: impl IntoIterator<Item = f64>) {
    out.push('[');
    for (i, v) in values.into_iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        let _ = write!(out, "{v}");
    }
    out.push(']');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::RobotConfig;
    use protocol_core::units::DeciMm;
    use serde_json::{Value, json};

    /// `text` as JSON, every number as a float (so 10 and 10.0 compare equal).
    fn parse(text: &str) -> Value {
        let value = serde_json::from_str(text).unwrap_or_else(|e| panic!("not JSON ({e}): {text}"));
        floats(value)
    }

    fn floats(value: Value) -> Value {
        match value {
            Value::Number(n) => json!(n.as_f64()),
            Value::Array(items) => Value::Array(items.into_iter().map(floats).collect()),
            Value::Object(fields) => {
                Value::Object(fields.into_iter().map(|(k, v)| (k, floats(v))).collect())
            }
            other => other,
        }
    }

    fn pose(v: [i16; 6]) -> Pose {
        Pose::from_array(v)
    }

    #[test]
    fn a_snapshot_travels_in_degrees_and_millimetres() {
        let snapshot = Snapshot {
            time_us: 1_500_000,
            angles: [1000, 2000, -3000, 1550, -2505, 4000].map(Centideg),
            coords: pose([1500, -634, 2001, -9000, 5, -9000]),
            end: EndType::Tool,
            reference: ReferenceFrame::World,
            tool: Some(pose([0, 0, 1000, 0, 0, 9000])),
            gripper_percent: 50,
            led_rgb: (255, 0, 16),
            powered: true,
            moving: false,
            dialect: Some(Dialect::Seed),
            collision: Some(CollisionMark {
                joint: 2,
                kind: Kind::JointMotion,
                time_us: 3_250_000,
            }),
            late: Lateness {
                total_us: 1_250,
                stalls: 2,
                worst_us: 1_000,
            },
            teach: Some(TeachStatus {
                activity: Activity::Playing,
                points: 81,
                played: 12,
                plays: 2,
                error: None,
            }),
        };
        assert_eq!(
            parse(&snapshot.to_json()),
            floats(json!({
                "t_s": 1.5,
                "angles_deg": [10.0, 20.0, -30.0, 15.5, -25.05, 40.0],
                "coords": [150.0, -63.4, 200.1, -90.0, 0.05, -90.0],
                "end": "tool",
                "frame": "world",
                "tool": [0.0, 0.0, 100.0, 0.0, 0.0, 90.0],
                "gripper": 50.0,
                "led": [255.0, 0.0, 16.0],
                "powered": true,
                "moving": false,
                "collision": {"joint": 2.0, "code": 16.0, "during": "moving joints", "t_s": 3.25},
                "late_ms": 1.25,
                "late_stalls": 2.0,
                "protocol": "seed",
                "basic_program": {
                    "name": "teach",
                    "activity": "playing",
                    "points": 81.0,
                    "played": 12.0,
                    "plays": 2.0,
                    "error": null,
                    "lines": ["now       PLAYING 12/81", "record    81 points, 4.0 s", "played    2 times"],
                },
            }))
        );
    }

    #[test]
    fn extreme_values_stay_valid_json() {
        let snapshot = Snapshot {
            time_us: u64::MAX,
            angles: [Centideg(i16::MIN); 6],
            coords: pose([i16::MAX; 6]),
            end: EndType::Flange,
            reference: ReferenceFrame::Base,
            tool: None,
            gripper_percent: 100,
            led_rgb: (0, 0, 0),
            powered: false,
            moving: true,
            dialect: None,
            collision: None,
            late: Lateness {
                total_us: u64::MAX,
                stalls: u32::MAX,
                worst_us: u64::MAX,
            },
            teach: None,
        };
        let value = parse(&snapshot.to_json());
        assert_eq!(value["angles_deg"][0], json!(-327.68));
        assert_eq!(value["coords"][0], json!(3276.7));
        assert_eq!(value["tool"], Value::Null);
        assert_eq!(value["end"], json!("flange"));
        assert_eq!(value["collision"], Value::Null);
        assert_eq!(value["protocol"], Value::Null);
        assert_eq!(value["basic_program"], Value::Null);
    }

    #[test]
    fn text_in_the_json_is_escaped() {
        let mut out = String::new();
        push_string(&mut out, "a \"quote\", a \\ and a\nline");
        assert_eq!(
            serde_json::from_str::<String>(&out).unwrap(),
            "a \"quote\", a \\ and a\nline"
        );
    }

    #[test]
    fn the_teach_lines_are_the_boards_screen_words() {
        let idle = TeachStatus::default();
        assert_eq!(
            teach_lines(&idle),
            [
                "now       move by hand after A",
                "record    0 points, 0.0 s",
                "played    0 times"
            ]
        );
        let recording = TeachStatus {
            activity: Activity::Recording,
            points: 81,
            ..idle
        };
        assert_eq!(teach_lines(&recording)[0], "now       RECORDING");
        assert_eq!(teach_lines(&recording)[1], "record    81 points, 4.0 s");
        let ready = TeachStatus {
            activity: Activity::Idle,
            points: 3,
            plays: 1,
            ..idle
        };
        assert_eq!(teach_lines(&ready)[0], "now       ready");
        assert_eq!(teach_lines(&ready)[2], "played    1 times");
    }

    #[test]
    fn a_robot_running_teach_carries_its_status_and_one_without_does_not() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(50_000);
        assert_eq!(Snapshot::of(&robot).teach, None);
        let mut teach = VirtualRobot::new(RobotConfig {
            basic_program: Some(crate::sim::BasicProgram::Teach),
            ..RobotConfig::default()
        });
        teach.run_for(50_000);
        let snapshot = Snapshot::of(&teach);
        assert_eq!(snapshot.teach, Some(TeachStatus::default()));
        let value = parse(&snapshot.to_json());
        assert_eq!(value["basic_program"]["activity"], json!("idle"));
        assert_eq!(value["basic_program"]["error"], Value::Null);
    }

    #[test]
    fn a_collision_is_marked_until_the_host_clears_it() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(1_500_000);
        assert_eq!(Snapshot::of(&robot).collision, None);
        robot.push_joint(3, 900);
        robot.run_for(100_000);
        let mark = Snapshot::of(&robot).collision.expect("marked");
        assert_eq!((mark.joint, mark.kind.code()), (3, 18));
        assert!((1_500_000..1_600_000).contains(&mark.time_us), "{mark:?}");
        robot.push_joint(3, 0);
        let clear = protocol_core::command::Request::ClearErrorInfo;
        assert!(robot.ask(&clear).is_ok());
        assert_eq!(Snapshot::of(&robot).collision, None);
    }

    #[test]
    fn a_fresh_robot_stands_straight_up_at_the_zero_pose() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(50_000);
        let snapshot = Snapshot::of(&robot);
        assert_eq!(snapshot.time_us, 50_000);
        assert_eq!(snapshot.angles, [Centideg(0); 6]);
        // docs/kinematics.md: the zero pose is (45.6, -63.4, 412.67) mm, (-90, 0, -90) deg.
        assert_eq!(snapshot.coords, pose([456, -634, 4126, -9000, 0, -9000]));
        assert_eq!((snapshot.end, snapshot.tool), (EndType::Flange, None));
        assert!(snapshot.powered);
    }

    #[test]
    fn the_snapshot_follows_the_shafts() {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot
            .servo_mut(2)
            .expect("servo 2")
            .move_by_hand(2048 + 512);
        let snapshot = Snapshot::of(&robot);
        assert_eq!(snapshot.angles, robot.measured_angles());
        assert_ne!(snapshot.angles[1], Centideg(0));
        assert_ne!(snapshot.coords.z, DeciMm(4126), "the flange came down");
    }

    #[test]
    fn the_model_is_kinematics_cores_dh_table() {
        let model = parse(&model_json(&ArmGeometry::MYCOBOT_280));
        assert_eq!(
            model,
            floats(json!({
                "d_mm": [131.22, 0.0, 0.0, 63.4, 75.05, 45.6],
                "a_mm": [0.0, -110.4, -96.0, 0.0, 0.0, 0.0],
                "alpha_deg": [90.0, 0.0, 0.0, 90.0, -90.0, 0.0],
                "theta_offset_deg": [0.0, -90.0, 0.0, -90.0, 90.0, 0.0],
            }))
        );
    }

    /// The page poses the arm with exactly this chain (arm.js): if the table it is served and
    /// the chain agree with kinematics-core here, the drawn flange is where get_coords says.
    #[test]
    fn the_served_table_chained_in_floating_point_gives_kinematics_cores_flange() {
        let model = parse(&model_json(&ArmGeometry::MYCOBOT_280));
        let column = |key: &str| -> Vec<f64> {
            model[key]
                .as_array()
                .expect("a list")
                .iter()
                .filter_map(Value::as_f64)
                .collect()
        };
        let (d, a, alpha, offset) = (
            column("d_mm"),
            column("a_mm"),
            column("alpha_deg"),
            column("theta_offset_deg"),
        );
        let kinematics = kinematics_core::Kinematics::new();
        for q_centideg in [
            [0, 0, 0, 0, 0, 0],
            [1000, 2000, -3000, 1500, -2500, 4000],
            [-12000, 9000, 13000, -14000, 15000, -17000],
        ] {
            let mut t = [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0],
            ];
            for i in 0..6 {
                let theta = (f64::from(q_centideg[i]) / 100.0 + offset[i]).to_radians();
                let (st, ct) = theta.sin_cos();
                let (sa, ca) = alpha[i].to_radians().sin_cos();
                let link = [
                    [ct, -st * ca, st * sa, a[i] * ct],
                    [st, ct * ca, -ct * sa, a[i] * st],
                    [0.0, sa, ca, d[i]],
                    [0.0, 0.0, 0.0, 1.0],
                ];
                let mut next = [[0.0; 4]; 4];
                for (r, row) in next.iter_mut().enumerate() {
                    for (c, cell) in row.iter_mut().enumerate() {
                        *cell = (0..4).map(|k| t[r][k] * link[k][c]).sum();
                    }
                }
                t = next;
            }
            let pose = kinematics.forward(&kinematics_core::JointAngles(q_centideg));
            for (axis, tenths) in [pose.x, pose.y, pose.z].into_iter().enumerate() {
                let mm = t[axis][3];
                assert!(
                    (mm - f64::from(tenths) / 10.0).abs() < 0.06,
                    "q {q_centideg:?} axis {axis}: chain {mm} mm, kinematics-core {tenths}"
                );
            }
        }
    }
}
