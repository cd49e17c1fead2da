//! The editor set-up in a real Neovim.

/// The Neovim set-up in `editors/neovim/scnc.lua`, in a real Neovim (Debian's: 0.7 on
/// Debian 12): a `.scn` file gets its file type and the server's diagnostics.
pub fn neovim_config_attaches_the_server() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("bad.scn");
    std::fs::write(&scene, "light ambient(1)\nobject sphre(1) at [0, 0, 5]\n").expect("writing the scene");
    let script = dir.path().join("check.lua");
    let config = std::fs::canonicalize("editors/neovim/scnc.lua").expect("the config");
    std::fs::write(
        &script,
        format!(
            r#"vim.cmd("filetype on")
dofile({config:?})
vim.cmd("edit " .. {scene:?})
vim.wait(10000, function() return #vim.diagnostic.get(0) > 0 end, 50)
local d = vim.diagnostic.get(0)
io.stdout:write(string.format("filetype=%s diagnostics=%d first=%s\n", vim.bo.filetype, #d, d[1] and d[1].message or "none"))
vim.cmd("qa!")
"#
        ),
    )
    .expect("writing the script");
    // The server is the binary under test, first on PATH.
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_scnc")).parent().expect("the binary's directory");
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let out = std::process::Command::new("nvim")
        .args(["--headless", "-u", "NONE", "-c", &format!("luafile {}", script.display())])
        .env("PATH", path)
        .env("HOME", dir.path())
        .output()
        .expect("running nvim");
    let text = String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(text.contains("filetype=scn diagnostics=1 first=unknown function `sphre`"), "{text}");
}
