-- scnc's language server in Neovim: diagnostics, hover, completion, signature help,
-- go to definition, references, symbols, quick fixes and formatting for `.scn` files.
--
-- Works on Neovim 0.7 and later: it uses `vim.lsp.config` and `vim.lsp.enable` where
-- they exist (0.11), `vim.lsp.start` on 0.8–0.10, and `vim.lsp.start_client` on 0.7
-- (Debian 12's). Copy it into `~/.config/nvim/plugin/`, or `dofile()` it from init.lua.
-- `scnc` must be on PATH (`cargo install --path .`).

vim.filetype.add({ extension = { scn = "scn" } })
-- 0.7 reads `vim.filetype.add` only with `g:do_filetype_lua` set; this works everywhere.
vim.api.nvim_create_autocmd({ "BufRead", "BufNewFile" }, { pattern = "*.scn", command = "setfiletype scn" })

local config = {
  name = "scnc",
  cmd = { "scnc", "lsp" },
  filetypes = { "scn" },
}

if vim.lsp.config and vim.lsp.enable then
  vim.lsp.config("scnc", config)
  vim.lsp.enable("scnc")
  return
end

-- Before 0.11: start (or reuse) the server for each `.scn` buffer, rooted at the
-- buffer's directory.
local clients = {}
vim.api.nvim_create_autocmd("FileType", {
  pattern = "scn",
  callback = function(args)
    local root = vim.fn.fnamemodify(vim.api.nvim_buf_get_name(args.buf), ":p:h")
    local settings = vim.tbl_extend("force", config, { root_dir = root })
    if vim.lsp.start then
      vim.lsp.start(settings, { bufnr = args.buf })
      return
    end
    if not clients[root] then
      clients[root] = vim.lsp.start_client(settings)
    end
    if clients[root] then
      vim.lsp.buf_attach_client(args.buf, clients[root])
    end
  end,
})
