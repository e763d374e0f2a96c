use super::*;
use crate::cores::testing::{data, events, frames, ms, node, rtr};

fn factor(n: u8) -> NonZeroU8 {
    NonZeroU8::new(n).unwrap()
}

#[test]
fn frame_layouts() {
    assert_eq!(guard_request(node(32)).to_string(), "720#R1");
    assert_eq!(
        guard_reply(node(32), true, NmtState::Operational),
        data(0x720, &[0x85])
    );
    assert_eq!(
        guard_reply(node(32), false, NmtState::PreOperational),
        data(0x720, &[0x7F])
    );
}

#[test]
fn master_requests_every_guard_time() {
    let mut g = NodeGuard::new();
    g.guard(ms(0), node(32), Duration::from_millis(100), factor(3));
    g.guard(ms(0), node(5), Duration::from_millis(100), factor(3));
    assert_eq!(g.poll_timeout(), Some(ms(0)));
    g.handle_timeout(ms(0));
    assert_eq!(frames(&mut g), [rtr(0x705), rtr(0x720)]);
    assert_eq!(g.poll_timeout(), Some(ms(100)));
    g.handle_timeout(ms(99));
    assert!(frames(&mut g).is_empty());
    g.handle_timeout(ms(100));
    assert_eq!(frames(&mut g).len(), 2);
    // A big jump: one request each, rescheduled from now.
    g.handle_timeout(ms(50_000));
    assert_eq!(frames(&mut g), [rtr(0x705), rtr(0x720)]);
    assert_eq!(g.poll_timeout(), Some(ms(50_100)));
}

#[test]
fn master_checks_toggle_and_tracks_state() {
    let mut g = NodeGuard::new();
    g.guard(ms(0), node(32), Duration::from_millis(100), factor(3));
    g.handle_frame(ms(1), &data(0x720, &[0x7F]));
    assert_eq!(
        events(&mut g),
        [GuardEvent::State {
            node: node(32),
            state: NmtState::PreOperational
        }]
    );
    g.handle_frame(ms(101), &data(0x720, &[0xFF]));
    g.handle_frame(ms(201), &data(0x720, &[0x05]));
    assert_eq!(
        events(&mut g),
        [GuardEvent::State {
            node: node(32),
            state: NmtState::Operational
        }]
    );
    // Toggle 0 again instead of 1: error, not a valid reply.
    g.handle_frame(ms(301), &data(0x720, &[0x05]));
    assert_eq!(events(&mut g), [GuardEvent::ToggleError { node: node(32) }]);
    // The life time still runs from the valid reply at 201 ms.
    g.handle_timeout(ms(500));
    assert!(events(&mut g).is_empty());
    g.handle_timeout(ms(501));
    assert_eq!(
        events(&mut g),
        [GuardEvent::LifeTimeExpired { node: node(32) }]
    );
    // Expectation follows the erroneous reply: next toggle is 1.
    g.handle_frame(ms(510), &data(0x720, &[0x85]));
    assert_eq!(events(&mut g), [GuardEvent::Resumed { node: node(32) }]);
    // Boot-up resets the toggle expectation to 0.
    g.handle_frame(ms(550), &data(0x720, &[0x00]));
    g.handle_frame(ms(560), &data(0x720, &[0x7F]));
    assert_eq!(
        events(&mut g),
        [
            GuardEvent::State {
                node: node(32),
                state: NmtState::BootUp
            },
            GuardEvent::State {
                node: node(32),
                state: NmtState::PreOperational
            }
        ]
    );
}

#[test]
fn master_life_time_expires_once() {
    let mut g = NodeGuard::new();
    g.guard(ms(0), node(7), Duration::from_millis(100), factor(3));
    for t in (0..=1000).step_by(50) {
        g.handle_timeout(ms(t));
        frames(&mut g);
        if t == 250 {
            assert!(events(&mut g).is_empty());
        }
    }
    assert_eq!(
        events(&mut g),
        [GuardEvent::LifeTimeExpired { node: node(7) }]
    );
    assert!(g.is_expired(node(7)));
    // A reply without an outstanding request counts too.
    g.handle_frame(ms(1010), &data(0x707, &[0x04]));
    assert_eq!(
        events(&mut g),
        [
            GuardEvent::Resumed { node: node(7) },
            GuardEvent::State {
                node: node(7),
                state: NmtState::Stopped
            }
        ]
    );
    g.handle_timeout(ms(1309));
    assert!(events(&mut g).is_empty());
    g.handle_timeout(ms(1310));
    assert_eq!(events(&mut g).len(), 1);
    // Forgotten: guarding off.
    g.forget(node(7));
    assert!(!g.is_guarded(node(7)));
    assert_eq!(g.poll_timeout(), None);
    // The objects' zeros mean "not used".
    assert_eq!(life_time(Duration::from_millis(100), 0), None);
    assert_eq!(life_time(Duration::ZERO, 3), None);
    assert_eq!(
        life_time(Duration::from_millis(100), 3),
        Some(Duration::from_millis(300))
    );
}

#[test]
fn master_and_responder_talk() {
    let mut g = NodeGuard::new();
    let mut r = GuardResponder::new(node(9));
    r.set_life_time(life_time(Duration::from_millis(50), 4));
    g.guard(ms(0), node(9), Duration::from_millis(50), factor(3));
    fn exchange(g: &mut NodeGuard, r: &mut GuardResponder, t: u64) {
        g.handle_timeout(ms(t));
        r.handle_timeout(ms(t));
        for f in frames(g) {
            r.handle_frame(ms(t), &f);
        }
        for f in frames(r) {
            g.handle_frame(ms(t), &f);
        }
    }
    let mut t = 0;
    // Nine replies: toggles 0, 1, ..., 0; the next one expected is 1.
    for _ in 0..9 {
        exchange(&mut g, &mut r, t);
        t += 50;
    }
    assert_eq!(
        events(&mut g),
        [GuardEvent::State {
            node: node(9),
            state: NmtState::PreOperational
        }]
    );
    // The node resets its toggle without a boot-up message: one error,
    // then the master follows.
    r.reset_toggle();
    for _ in 0..3 {
        exchange(&mut g, &mut r, t);
        t += 50;
    }
    assert_eq!(events(&mut g), [GuardEvent::ToggleError { node: node(9) }]);
    assert!(events(&mut r).is_empty());
    // The master stops guarding: the node detects it.
    g.forget(node(9));
    for _ in 0..5 {
        exchange(&mut g, &mut r, t);
        t += 50;
    }
    assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingLost]);
}

#[test]
fn responder_answers_with_alternating_toggle() {
    let mut r = GuardResponder::new(node(32));
    r.handle_frame(ms(0), &data(0x720, &[0x00]));
    r.handle_frame(ms(0), &rtr(0x721));
    assert!(frames(&mut r).is_empty());
    r.handle_frame(ms(0), &rtr(0x720));
    assert_eq!(frames(&mut r), [data(0x720, &[0x7F])]);
    r.set_state(NmtState::Operational);
    r.handle_frame(ms(0), &rtr(0x720));
    assert_eq!(frames(&mut r), [data(0x720, &[0x85])]);
    r.handle_frame(ms(0), &rtr(0x720));
    assert_eq!(frames(&mut r), [data(0x720, &[0x05])]);
    r.handle_frame(ms(0), &rtr(0x720));
    r.reset_toggle();
    r.set_state(NmtState::Stopped);
    assert_eq!(frames(&mut r), [data(0x720, &[0x04])]);
    assert_eq!(r.poll_timeout(), None);
}

#[test]
fn responder_detects_life_guarding_loss() {
    let mut r = GuardResponder::new(node(3));
    r.set_life_time(life_time(Duration::from_millis(100), 2));
    // Not before the first request.
    assert_eq!(r.poll_timeout(), None);
    r.handle_frame(ms(1000), &rtr(0x703));
    assert_eq!(r.poll_timeout(), Some(ms(1200)));
    r.handle_timeout(ms(1199));
    assert!(events(&mut r).is_empty());
    r.handle_timeout(ms(1200));
    assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingLost]);
    assert!(r.is_lost());
    r.handle_timeout(ms(5000));
    assert!(events(&mut r).is_empty());
    r.handle_frame(ms(5000), &rtr(0x703));
    assert_eq!(events(&mut r), [GuardResponderEvent::LifeGuardingResumed]);
    // Both requests were answered by one reply (not polled in between).
    assert_eq!(frames(&mut r), [data(0x703, &[0x7F])]);
}
