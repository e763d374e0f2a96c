use super::*;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eds2rust-bounded-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("project/eds")).unwrap();
    dir
}

#[test]
fn base_inside_the_project_passes_and_outside_is_refused() {
    let dir = scratch("base");
    let project = dir.join("project");
    std::fs::write(project.join("eds/base.eds"), "x").unwrap();
    std::fs::write(dir.join("outside.eds"), "x").unwrap();
    let inside = project.join("eds/base.eds");
    assert_eq!(check_base(&inside, Some(&project), &[]), Ok(()));
    // `..` out of the project.
    let up = project.join("eds/../../outside.eds");
    assert!(check_base(&up, Some(&project), &[]).is_err());
    // A symbolic link inside the project that points out of it.
    #[cfg(unix)]
    {
        let link = project.join("eds/link.eds");
        std::os::unix::fs::symlink(dir.join("outside.eds"), &link).unwrap();
        let err = check_base(&link, Some(&project), &[]).unwrap_err();
        assert!(err.contains("outside.eds"), "{err}");
    }
    // Allowed explicitly.
    assert_eq!(
        check_base(&up, Some(&project), std::slice::from_ref(&dir)),
        Ok(())
    );
    // A path that does not exist reads nothing: the reader reports it.
    assert_eq!(
        check_base(&project.join("missing.eds"), Some(&project), &[]),
        Ok(())
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn limits_count_bytes() {
    let dir = scratch("limit");
    let file = dir.join("ten.eds");
    std::fs::write(&file, [b'x'; 10]).unwrap();
    assert_eq!(read_input(&file, 10).unwrap().len(), 10);
    assert!(matches!(
        read_input(&file, 9),
        Err(Refused::TooLarge {
            limit: 9,
            size: Some(10)
        })
    ));
    assert!(matches!(read_input(&dir, 10), Err(Refused::NotAFile(_))));
    assert!(matches!(
        read_input(&dir.join("missing"), 10),
        Err(Refused::Io(_))
    ));
    assert_eq!(human(64 << 20), "67108864 bytes (64 MiB)");
    assert_eq!(human(1000), "1000 bytes");
    let _ = std::fs::remove_dir_all(&dir);
}
