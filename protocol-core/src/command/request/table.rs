//! The `requests!` macro: turns the table of commands in `request.rs` into the [`Request`] enum
//! and every match over it.
//!
//! Each command is one entry of the table, its doc, fields, code, reply, layout, parse and
//! emit side by side, and each match below is generated with one arm per entry and no
//! wildcard arm, so a command cannot be added to one match and forgotten in another:
//!
//! ```text
//! /// 0x21 send one joint angle.            doc of the variant
//! SendAngle { joint: JointId, .. }          the variant and its fields
//!     = cmd::SEND_ANGLE,                    the CMD byte
//!     reply ReplyKind::Ack,                 what it is answered with (may read the fields)
//!     data 4                                LEN - 2 of this layout: a pattern (`13 | 14`)
//!         => |f| Self::SendAngle { .. },    parse: `f` reads the data field by field
//!     emit |w| { w.u8(joint.get()); .. };   encode: writes the fields (all must be used)
//! ```
//!
//! A command without fields is one line, `Name = cmd::CODE, reply ReplyKind::Kind;`: its only
//! layout is LEN 2 (no data) and nothing is emitted.
//!
//! Generated: the [`Request`] enum, [`RequestKind`] (the variants without their fields, and
//! [`RequestKind::ALL`] that the property tests draw every command from), [`Request::kind`],
//! [`RequestKind::cmd`], [`Request::reply_kind`], and the private `parse_data` / `emit` that
//! [`Request::parse`] and [`Request::to_frame`] are built on.
//!
//! [`Request`]: super::Request
//! [`RequestKind`]: super::RequestKind
//! [`RequestKind::ALL`]: super::RequestKind::ALL
//! [`RequestKind::cmd`]: super::RequestKind::cmd
//! [`Request::kind`]: super::Request::kind
//! [`Request::reply_kind`]: super::Request::reply_kind
//! [`Request::parse`]: super::Request::parse
//! [`Request::to_frame`]: super::Request::to_frame

macro_rules! requests {
    (
        $(#[$meta:meta])*
        pub enum Request {
            $(
                $(#[$doc:meta])*
                $variant:ident $({
                    $( $(#[$field_doc:meta])* $field:ident: $ty:ty ),* $(,)?
                })?
                = $code:path, reply $reply:expr
                $(, data $len:pat => |$f:ident| $parse:expr, emit |$w:ident| $emit:block)?
                ;
            )*
        }
    ) => {
        $(#[$meta])*
        pub enum Request {
            $(
                $(#[$doc])*
                $variant $({ $( $(#[$field_doc])* $field: $ty ),* })?,
            )*
        }

        /// Which command a [`Request`] is, without its fields: one variant per request variant.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum RequestKind {
            $(
                #[doc = concat!("[`Request::", stringify!($variant), "`].")]
                $variant,
            )*
        }

        impl RequestKind {
            /// Every kind, in the order of the table in `request.rs`.
            pub const ALL: &'static [Self] = &[$(Self::$variant),*];

            /// The command code (CMD byte) of this kind of request.
            pub const fn cmd(self) -> u8 {
                match self {
                    $(Self::$variant => $code,)*
                }
            }
        }

        impl Request {
            /// Which command this is, without its fields.
            pub const fn kind(&self) -> RequestKind {
                match self {
                    $(Self::$variant { .. } => RequestKind::$variant,)*
                }
            }

            /// Shape of the reply this request expects (`protocol.md` section 5), for
            /// [`Reply::parse`](super::Reply::parse).
            pub fn reply_kind(&self) -> ReplyKind {
                match self {
                    $(
                        #[allow(unused_variables)]
                        Self::$variant $({ $($field),* })? => $reply,
                    )*
                }
            }

            /// The request of command `code` whose layout has `fields.remaining()` data
            /// bytes; the frame's bad-length error if no layout of `code` has that many.
            fn parse_data(code: u8, fields: &mut Fields<'_>) -> Result<Self, CommandError> {
                Ok(match (code, fields.remaining()) {
                    $(
                        ($code, requests!(@data_len $($len)?)) => {
                            requests!(@parse fields, Self::$variant $(, |$f| $parse)?)
                        }
                    )*
                    _ => return Err(fields.bad_len()),
                })
            }

            /// Writes this request's data bytes.
            fn emit(&self, writer: &mut Writer) {
                match self {
                    $(
                        Self::$variant $({ $($field),* })? => {
                            $(let $w: &mut Writer = writer; $emit)?
                        }
                    )*
                }
            }
        }
    };

    // A command without fields has one layout, no data...
    (@data_len) => { 0 };
    (@data_len $len:pat) => { $len };
    // ...and parses to itself.
    (@parse $fields:ident, $unit:path) => { $unit };
    (@parse $fields:ident, $variant:path, |$f:ident| $parse:expr) => {{
        let $f = &mut *$fields;
        $parse
    }};
}

pub(super) use requests;
